// The outline mesher: the stroke a finger drew on the table, filled with the seed's lattice. GLM only:
// it knows nothing of the engine; drape::sim::constrainMesh (drape/sim/cloth.hpp) gives the mesh its
// stretch, shear and bend constraints by the lattice positions this leaves on its particles.
//
// The table is the x-z plane; a point of the stroke is (x, z) in metres. "Counter-clockwise seen from +y" is defined
// by the same sign that makes the lattice's triangle normals point +y: points p0, p1, p2 are counter-clockwise when
// cross(p1 - p0, p2 - p0).y > 0 with p = (x, 0, z), i.e. (p1.z - p0.z) (p2.x - p0.x) - (p1.x - p0.x) (p2.z - p0.z) > 0.
// (Looking down from +y with x to the right, +z points down the page.)
//
// How a stroke becomes a mesh (src/loop.cpp: steps 1 to 3; src/fill.cpp: step 4; exact integer geometry in
// src/exact.hpp):
//  1. Clean. A non-finite point is an error. Points are held as integers on a grid of 1/4096 spacing, so that every
//     later geometric decision is exact and cannot contradict another (the loop moves by at most 0.07% of a spacing).
//     Points closer than spacing/4 to the previous kept point are dropped, the stroke is simplified with
//     Douglas-Peucker (tolerance spacing/4) and closed: the last point joins the first.
//  2. Untangle. Walking along the closed stroke, whenever it crosses or touches its own path so far, the loop it has
//     just closed is cut off and the walk continues from the crossing (a figure-eight is cut at its waist). Every loop
//     cut off is simple; the one enclosing the largest area is kept, and tookLargestLoop says the stroke was split
//     into more than one loop with area. A figure-eight keeps its larger lobe; a circle drawn with an overshoot past
//     its start keeps the circle. Edges shorter than spacing/3 (left by crossings) are then removed where that keeps
//     the loop simple.
//  3. Orient. The loop is made counter-clockwise seen from +y.
//  4. Fill. The lattice (spacing apart along x and z, with a node at the stroke's smallest x and z, and the
//     lattice's own diagonal in each cell) is clipped exactly against the loop: triangles inside stay as they are,
//     triangles the loop crosses become the part of them inside the loop, triangulated. So the mesh covers the loop
//     exactly (total area = the loop's area), every corner of the loop is a particle and every boundary edge lies
//     on the loop. The slivers clipping leaves are then removed by collapsing short edges, shortest first: a lattice
//     node closer than spacing/2 to a boundary particle moves onto it (sweeping up loop points within 0.75 spacing
//     that would otherwise flatten), and boundary particles closer than 0.4 spacing along the loop merge; a corner
//     of the loop never goes. A collapse is undone unless every triangle it changed stays counter-clockwise and is
//     either good (quality >= 0.25, 1 being equilateral and 0.87 the lattice's half cell) or at least half as good
//     as before. Edges are flipped where that clearly improves a poor triangle (where the loop turns gently, three
//     of its points can make one). A boundary particle then takes the lattice position (column, row) of the nearest
//     unclaimed node outside the loop within spacing/2, so that the border joins in the lattice's constraints.
//     The mesh keeps each particle's lattice position (column, row), where it has one: every node of the lattice
//     inside the loop, and the border particles that claimed one.
#pragma once

#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace drape::mesh {

// The most particles a mesh may have: the engine's limit over all cloths (drape::sim::kMaxParticles).
inline constexpr long long kMaxParticles = 1 << 20;

struct OutlineSpec {
  std::vector<glm::dvec2> points;  // the stroke, in the table plane: (x, z) in metres, as drawn (not closed)
  double spacing = 0.05;           // m, lattice spacing of the fill, > 0
  double height = 0.0;             // m, y of the cloth (it lies flat in the x-z plane)
};

// (column, row) of a particle that stands for no lattice node.
inline constexpr glm::ivec2 kNoNode{-1, -1};

struct OutlineMesh {
  std::vector<glm::dvec3> positions;  // m, every particle's, at y = height
  std::vector<glm::uvec3> triangles;  // counter-clockwise seen from +y
  // Each particle's lattice position (column, row), counted from the lattice's own origin (a node at
  // the stroke's smallest x and z, less a margin), or kNoNode. Diagonal neighbours on the lattice are
  // joined by its diagonal, as in the seed's lattice: (column + 1, row) with (column, row + 1).
  std::vector<glm::ivec2> nodes;
  // The simple closed loop the cloth fills, counter-clockwise seen from +y, first point not repeated.
  // Its corners are particles and the cloth's boundary edges lie on it.
  std::vector<glm::dvec2> loop;
  bool tookLargestLoop = false;  // true when the stroke crossed itself and the largest simple loop was kept
};

// Meshes a cloth cut to the outline. Throws std::invalid_argument with a one-line message when the
// outline cannot make a cloth: spacing or height not finite (spacing under 1e-9 m), a non-finite point,
// fewer than 3 distinct points, no enclosed area (collinear points), smaller than one cell (area under
// spacing^2), wider than 2^17 spacings or 1e38 m, more particles than kMaxParticles (estimated from area and
// perimeter before anything is allocated; the message says how many), or too intricate (so much detail
// finer than the spacing that untangling or filling it would take more than about half a second).
// Deterministic: the same spec gives the same mesh.
OutlineMesh meshOutline(const OutlineSpec& spec);

}  // namespace drape::mesh
