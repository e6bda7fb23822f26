// A cloth's rest description: what it is, as opposed to where it is (state.hpp).
//
// The lattice follows the seed (Provot 1995): particles on a regular grid joined by distance
// constraints of three kinds that resist stretching (structural neighbours), shearing (diagonal
// neighbours) and bending (neighbours two apart). Triangles exist for rendering, normals and
// aerodynamic forces. Rest data is built once and never changes while the cloth is simulated.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "drape/sim/types.hpp"

namespace drape::sim {

enum class ConstraintKind : std::uint8_t { stretch, shear, bend };
inline constexpr std::size_t kConstraintKindCount = 3;
inline constexpr std::array<ConstraintKind, kConstraintKindCount> kConstraintKinds = {
    ConstraintKind::stretch, ConstraintKind::shear, ConstraintKind::bend};
std::string_view name(ConstraintKind kind);

// Two particles that want to stay restLength apart.
struct DistanceConstraint {
  ParticleIndex a;
  ParticleIndex b;
  RestReal restLength;  // m
  bool operator==(const DistanceConstraint&) const = default;
};

// A rest length as the engine keeps it (RestReal). Throws std::invalid_argument where `length` is
// not a finite non-negative number that single precision holds, or is positive but rounds to 0.
RestReal toRestLength(Real length);
// ... rounded up instead of to the nearest: the least RestReal not below `length`. For a length
// that must not come out shorter (a tether: the rest shape must lie within it).
RestReal toRestLengthAtLeast(Real length);

// Which world plane the lattice is laid out in at rest.
enum class LatticePlane : std::uint8_t {
  xz,  // lying flat: columns along +x, rows along +z, at height origin.y
  xy,  // hanging: columns along +x, rows downwards along -y
};
std::string_view name(LatticePlane plane);

struct LatticeSpec {
  int columns = 2;    // particles along a row, >= 1
  int rows = 2;       // particles along a column, >= 1 (1 makes a chain)
  Real width = 1.0;   // m, distance from column 0 to the last column
  Real height = 1.0;  // m, distance from row 0 to the last row
  Vec3 origin{0.0};   // m, rest position of particle (column 0, row 0)
  LatticePlane plane = LatticePlane::xz;
};

// A fabric's bending at one particle (ClothSettings::fabric): C = sqrt(A) times the discrete
// Laplacian of the positions there, where A is the particle's share of the area (a third of its
// triangles'). C is linear in the positions and 0 while the sheet is flat; the stencil stores E = B /
// 2 |C|^2 (B the bending rigidity, N m), so E is B / 2 (k1 + k2)^2 A: for a sheet that does not
// stretch (k1 k2 = 0) the plate's energy, whichever way it bends (Bergou, Wardetzky, Harmon, Zorin
// and Grinspun 2006; Wardetzky, Bergou, Harmon, Zorin and Grinspun 2007). Inside the cloth (its
// triangles close all round the particle) the Laplacian is the cotangent one, 1 / (2 A) sum_j
// (cot a_j + cot b_j) (x_j - x), which is exact for a linear field on any mesh, so a drawn cloth's
// clipped cells bend as its lattice does; on a square lattice's cells it is the lattice's own
// five-point Laplacian. Along a border only the border's line counts (its two links that point
// opposite ways at rest, within 8 degrees), the curve's curvature vector 2 / (la + lb) ((x_a - x) /
// la + (x_b - x) / lb): a free edge carries no moment across itself. v[0] is the particle itself,
// with k[0] = -(k[1] + ... ); the neighbours follow, each k non-zero, and an unused entry after
// them is v[0] again with k 0 (so the first k 0 ends a stencil).
inline constexpr int kBendStencilSize = 9;  // the particle and up to 8 neighbours
struct BendStencil {
  std::array<ParticleIndex, kBendStencilSize> v;
  std::array<RestReal, kBendStencilSize> k;  // 1/m; C = sum_{j>0} k_j (x_j - x_0)
  bool operator==(const BendStencil&) const = default;
};
// How many entries a stencil uses: the particle and its neighbours, up to the first k 0.
inline int stencilSize(const BendStencil& b) {
  int used = 1;
  while (used < kBendStencilSize && b.k[used] != 0.0f) ++used;
  return used;
}

struct ClothRest {
  int columns = 0;
  int rows = 0;
  // Rest positions in single precision, as offsets from the cloth's own origin: 12 bytes a particle
  // instead of 24, and rounded relative to the cloth's size (6e-8 of it), wherever the cloth is in
  // the world. The origin is the first particle's rest position (setRestPositions), so positions
  // written out as doubles (snapshots) and set again give back the same origin and offsets.
  Vec3 restOrigin{0.0};                // m
  std::vector<glm::vec3> restOffsets;  // m from restOrigin, index = row * columns + column
  std::vector<glm::uvec3> triangles;   // counter-clockwise seen from the front (+y or +z)
  std::array<std::vector<DistanceConstraint>, kConstraintKindCount> constraints;  // by kind
  std::vector<BendStencil> bending;  // a fabric's (buildBendStencils); empty otherwise

  std::size_t particleCount() const { return restOffsets.size(); }
  Vec3 restPosition(std::size_t i) const { return restOrigin + Vec3(restOffsets[i]); }  // m
  // Sets every rest position, the first one as the origin. Throws std::invalid_argument where a
  // position is not finite or lies beyond single precision's range (3.4e38 m) from the first.
  void setRestPositions(const std::vector<Vec3>& positions);
  // A new particle at particle i's rest position (tearing splits a particle into copies).
  void duplicateRestPosition(std::size_t i) { restOffsets.push_back(glm::vec3(restOffsets[i])); }
  ParticleIndex index(int column, int row) const { return static_cast<ParticleIndex>(row * columns + column); }
  const std::vector<DistanceConstraint>& of(ConstraintKind kind) const {
    return constraints[static_cast<std::size_t>(kind)];
  }
};

// Which constraint kinds to generate: a kind the cloth does not use costs no memory and no time.
struct ConstraintSelection {
  bool stretch = true;
  bool shear = true;
  bool bend = true;
};

// A triangle's area at rest, and each particle's share of the area: a third of each of its triangles'.
Real triangleArea(const ClothRest& rest, const glm::uvec3& triangle);
std::vector<Real> particleAreas(const ClothRest& rest);

// Every particle's bend stencil, from the triangles (the cotangent weights and the areas) where
// they go once round the particle, and elsewhere from the stretch constraints: a line through a
// particle is two of its stretch links that point opposite ways at rest (within 8 degrees), at most
// two lines. A particle inside whose cotangent stencil cannot be had (more than 8 neighbours with a
// weight, or a triangle under about a degree) takes its lines instead. A particle on no line and
// with no cotangent stencil (a border's corner, a tear's tip) gets none.
std::vector<BendStencil> buildBendStencils(const ClothRest& rest);

// (column, row) of a particle that stands for no lattice node (LatticeMesh::nodes).
inline constexpr glm::ivec2 kNoNode{-1, -1};

// A triangle mesh whose particles may stand for nodes of the seed's square lattice: a lattice's own
// (buildLattice), or a drawn cloth's (drape/mesh/outline.hpp makes one from a stroke), whose border
// particles off the lattice stand for none. A cell's diagonal neighbours are (column, row) and
// (column + 1, row + 1), or (column + 1, row) and (column, row + 1).
struct LatticeMesh {
  std::vector<Vec3> positions;        // m, at rest
  std::vector<glm::uvec3> triangles;  // counter-clockwise seen from the front
  std::vector<glm::ivec2> nodes;      // each particle's (column, row) on the lattice, or kNoNode
  Real spacing = 0.0;                 // m, the lattice's (a cut snaps at it)
};

// The one place the seed's constraints are made, for the lattice and for a drawn cloth, by lattice
// position: every triangle edge between diagonal neighbours is shear, and so is the other diagonal
// of a whole cell (split by its two triangles along one diagonal); every other triangle edge is
// stretch (on a drawn cloth's border, edges between particles off the lattice are stretch as well);
// bend joins particles two apart along a row or column where both stretch edges through the middle
// particle exist and the two are not joined by an edge themselves. A mesh without triangles is a
// chain: its edges are the lattice's row and column neighbours. Rest lengths are measured on the
// rest positions as rounded (ClothRest::setRestPositions); an edge between particles that coincide
// there gets no constraint. The lists come in the engine's one order (orderConstraints). Border
// triangles without a lattice bend across them get no extra
// bending constraint. Throws std::invalid_argument where the mesh is not one: nodes not one per
// particle, a node off the lattice (negative) or stood for twice, a triangle with a corner out of
// range or twice, a position not finite.
ClothRest constrainMesh(const LatticeMesh& mesh, ConstraintSelection selection = {});
// The rules constrainMesh makes a mesh's constraints by, over `triangles` of a cloth whose rest
// positions `rest` has, each particle standing for lattice node nodes[p] (or kNoNode; one a
// particle): what constrainMesh puts in its lists, in lattice order: stretch by particle pair
// (a < b), shear by cell, row by row, its diagonal (column, row)-(column + 1, row + 1) first, bend
// by first node, row by row, along the row first. Tearing makes the links of the edges a split
// triangle's children add so (topology.cpp): a particle it inserts stands for no node, so each such
// edge is stretch. Throws std::invalid_argument as constrainMesh does.
std::array<std::vector<DistanceConstraint>, kConstraintKindCount> meshConstraints(
    const ClothRest& rest, const std::vector<glm::uvec3>& triangles, const std::vector<glm::ivec2>& nodes,
    ConstraintSelection selection = {});

// Puts a cloth's constraints in the one order the engine keeps them in, whichever solver runs:
// stretch in line order (the rows' links line by line, each turned to point along its row, then the
// columns', then the links on no line), shear and bend each in batches no two of whose constraints
// share a particle (so a batch can be shared among threads). constrainMesh's lists come in it; the
// world puts a cloth's in it as the cloth enters and as it is torn or cut; no solver reorders them.
// Putting them in it again changes nothing. `source` (a torn cloth's Topology::source: per
// constraint, the recipe it came from) and `stretchTension` (Cloth::stretchTension) move with
// them where they have one entry a constraint; a tension that has not is stale, and emptied.
void orderConstraints(ClothRest& rest, std::array<std::vector<std::uint32_t>, kConstraintKindCount>* source = nullptr,
                      std::vector<float>* stretchTension = nullptr);

// Builds the lattice (by constrainMesh). Throws std::invalid_argument if the spec is not a valid
// lattice.
ClothRest buildLattice(const LatticeSpec& spec, ConstraintSelection selection = {});

}  // namespace drape::sim
