// What a cloth needs to know about its own connectivity once its mesh can change (tearing, cutting).
//
// Tearing and cutting never delete material: they split particles (and a cut first splits the
// triangles it crosses, with new particles on their edges: topology::cut). The triangles are the truth:
// two triangles that share an edge are joined across it until that edge is severed, and every
// particle is one fan of triangles around a point. Severing edges and then splitting each particle
// whose fan fell apart into one particle per remaining fan opens the mesh for real, so no triangle
// spans a tear, and the particle's mass is shared among its copies by the rest area each fan
// covers, so mass is conserved exactly.
//
// Every distance constraint is kept as a recipe over triangles (a "template") and rebuilt from the
// triangles after each change: an edge of a triangle stays between that triangle's corners; a
// quad's other diagonal lives while its two triangles are joined; a bend (two apart, through a
// middle particle) lives while both its halves still meet at the same middle particle. Constraints
// no triangle witnesses (a chain) simply break.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "drape/sim/cloth.hpp"
#include "drape/sim/types.hpp"

namespace drape::sim {

struct ConstraintTemplate {
  enum class Link : std::uint8_t {
    same,     // a and b are corners of one triangle
    across,   // a in t1, b in t2, and t1, t2 joined across edge `edge1` of t1
    through,  // a in t1, b in t2, and t1's corner `middle1` is t2's corner `middle2`
    free,     // no triangle: a = t1, b = t2 are particles; `broken` once torn or cut
  };
  RestReal restLength = 0.0f;
  std::uint32_t t1 = 0, t2 = 0;
  ConstraintKind kind = ConstraintKind::stretch;
  Link link = Link::same;
  std::uint8_t corner1 = 0, corner2 = 0;  // of a in t1, of b in t2
  std::uint8_t middle1 = 0, middle2 = 0;  // through: corners of the middle particle; across: edge1 = middle1
  bool broken = false;
};

// A particle that was split: `copy` is new, made from `original` (both keep its rest position).
struct ParticleSplit {
  ParticleIndex original;
  ParticleIndex copy;
};

// A particle a cut put on the edge a-b where the cut crossed it: at a + s (b - a), at rest and now.
struct ParticleInsert {
  ParticleIndex a;
  ParticleIndex b;
  Real s;
  ParticleIndex particle;
};

struct Topology {
  bool built = false;
  // Per triangle, the triangle joined to it across edge k (corners k and k+1 mod 3), or -1.
  std::vector<std::array<std::int32_t, 3>> neighbour;
  std::vector<Real> triangleArea;  // m^2, at rest
  std::vector<ConstraintTemplate> templates;
  std::size_t torn = 0;  // edges severed and links broken so far (tearing and cutting)
  // Per current constraint, by kind: the template it came from.
  std::array<std::vector<std::uint32_t>, kConstraintKindCount> source;
  // Per triangle, for tearing: its rest frame (u, w: unit vectors in its plane at rest) and the
  // edges' coordinates in it (corner 1 at (a, 0), corner 2 at (b, d)); made again after a change.
  struct RestFrame {
    glm::vec3 u, w;
    float a, b, d;
  };
  std::vector<RestFrame> restFrames;
  // Where the last cut segment ended inside a triangle: the particles it left on that triangle's
  // edge, which the next segment of the same swipe (starting at `cutEnd`) carries the cut on from.
  std::vector<ParticleIndex> cutTips;
  Vec3 cutEnd{0.0};
};

}  // namespace drape::sim
