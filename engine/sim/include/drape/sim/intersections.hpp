// Counting where cloth passes through cloth: the pairs of triangles that intersect.
//
// The measure of self-contact (docs/design.md): a cloth that never passes through itself has none,
// whatever its particles' distances say. Exact on the mesh with its positions rounded to a grid of
// 2^-24 m (60 nm): on that grid every orientation test is an integer determinant computed without
// rounding (128-bit), so the count never depends on the order of operations or a tolerance, and two
// triangles touching are told apart from two crossing.
//
// Which pairs: every two triangles of the world (of one cloth or of two) that share no particle and
// whose closed triangles have a point in common; and two of one cloth that share one particle when
// the edge of one opposite it passes through the other (a fold through a vertex). Two triangles
// that share an edge are counted only when one lies folded flat onto the other: their other corners
// in one plane with the edge and on one side of it there (a triangle turned over on a table, onto
// its neighbour). A flat sheet has none; two sheets crossing like the pages of a half-open book
// have one pair per pair of triangles along the crossing line.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

#include "drape/sim/types.hpp"

namespace drape::sim {

class World;

// Triangles `triangles` over `positions` (m, within +-10^4 of the origin; a triangle with a corner
// beyond that, or not finite, is left out and counted in `skipped`).
struct IntersectionCount {
  std::size_t pairs = 0;    // intersecting triangle pairs
  std::size_t skipped = 0;  // triangles not tested (a corner non-finite or beyond 10^4 m)
};
IntersectionCount countIntersections(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& triangles);
// As above, with which corners two triangles share told by `shared` (the same size as `triangles`):
// a corner there names the particle it counts as.
IntersectionCount countIntersections(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& triangles,
                                     const std::vector<glm::uvec3>& shared);

// Every cloth of the world together: pairs within a cloth and between cloths. In a torn or cut
// cloth, particles at one point of the grid count as one corner (the copies a tear makes, before
// the seam opens: the triangles on its two sides touch there, as they did before it).
IntersectionCount countIntersections(const World& world);

}  // namespace drape::sim
