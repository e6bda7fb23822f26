// The outline mesher's step 4 (drape/mesh/outline.hpp): the lattice clipped exactly against a simple
// loop; internal.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "exact.hpp"

namespace drape::mesh::detail {

constexpr std::int32_t kNone = -1;

struct Vertex {
  glm::dvec2 position{0.0};      // integer frame
  std::int64_t node = kNone;     // lattice node key (row * (columns + 1) + column), if it stands for one
  std::int32_t segment = kNone;  // on this loop segment (between its ends)
  std::int32_t corner = kNone;   // this loop point
  bool movable = false;          // a node of a clipped triangle: may move onto the loop
  bool listed = false;           // knows its triangles (on the loop, movable, or next to a movable node)
  bool alive = true;
  bool onLoop() const { return segment != kNone || corner != kNone; }
};

using Triangle = std::array<std::uint32_t, 3>;

// Twice the signed area of p, q, r (in the integer frame, as doubles): positive when counter-clockwise seen from +y.
inline double orient(const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& r) {
  return (q.y - p.y) * (r.x - p.x) - (q.x - p.x) * (r.y - p.y);
}

struct Fill {
  std::vector<Vertex> vertices;  // nodes row by row, then loop points, then crossings; some dead
  std::vector<Triangle> triangles;
  std::vector<char> alive;  // per triangle
  Coord columns = 0;        // cells along x: a node's key is row * (columns + 1) + column
};

// Fills `loop` (simple, counter-clockwise, in the integer frame: kUnitsPerSpacing units a spacing of
// `spacing` m, which only words the errors).
Fill fillLoop(const std::vector<Point>& loop, double spacing);

}  // namespace drape::mesh::detail
