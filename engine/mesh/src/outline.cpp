#include "drape/mesh/outline.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/common.hpp>

#include "exact.hpp"
#include "fill.hpp"
#include "loop.hpp"

namespace drape::mesh {

using namespace detail;

namespace {

constexpr Coord kMarginCells = 2;           // empty lattice cells around the stroke
constexpr double kMaxSpanCells = 131072.0;  // 2^17: keeps coordinates below 2^30
constexpr double kMaxSpan = 1e38;           // m, within single precision's 3.4e38 with room to spare

}  // namespace

OutlineMesh meshOutline(const OutlineSpec& spec) {
  checkStroke(spec);
  glm::dvec2 low = spec.points[0], high = spec.points[0];
  for (const glm::dvec2& p : spec.points) {
    low = glm::min(low, p);
    high = glm::max(high, p);
  }
  // Halved so that points at +-1e308 do not overflow.
  const double halfSpan = std::max(high.x / 2.0 - low.x / 2.0, high.y / 2.0 - low.y / 2.0);
  if (!(halfSpan / spec.spacing <= kMaxSpanCells / 2.0)) {
    fail("outline spans " + number(2.0L * halfSpan) + " m, more than " +
         std::to_string(static_cast<long long>(kMaxSpanCells)) + " spacings of " + number(spec.spacing) + " m");
  }
  // The engine holds a cloth's rest positions as single-precision offsets from its first particle.
  if (!(halfSpan <= kMaxSpan / 2.0)) {
    fail("outline spans " + number(2.0L * halfSpan) + " m, more than the " + number(kMaxSpan) +
         " m single precision holds");
  }
  Frame frame;
  frame.unit = spec.spacing / static_cast<double>(kUnitsPerSpacing);
  frame.origin = low - glm::dvec2(static_cast<double>(kMarginCells) * spec.spacing);

  const Loop loop = loopFromStroke(spec, frame);
  const Fill fill = fillLoop(loop.points, spec.spacing);

  OutlineMesh result;
  result.tookLargestLoop = loop.tookLargest;
  result.loop.reserve(loop.points.size());
  for (const Point& p : loop.points) result.loop.push_back(frame.toWorld(p));

  // Keep the live triangles; a numerically flat one can only be left where points coincide, and covers nothing.
  const std::vector<Vertex>& vertices = fill.vertices;
  const double flat = 1e-9 * static_cast<double>(kUnitsPerSpacing * kUnitsPerSpacing);
  std::vector<Triangle> triangles;
  for (std::size_t t = 0; t < fill.triangles.size(); ++t) {
    if (!fill.alive[t]) continue;
    const Triangle& tri = fill.triangles[t];
    const double o = orient(vertices[tri[0]].position, vertices[tri[1]].position, vertices[tri[2]].position);
    if (o > flat) {
      triangles.push_back(tri);
    } else if (o < -flat) {
      fail("outline could not be meshed at spacing " + number(spec.spacing) +
           " m (internal check failed: folded triangle)");
    }
  }
  if (triangles.empty()) fail(tooSmall(0.0, spec.spacing));

  // Particles in vertex order (nodes row by row, then loop points, then crossings), unused ones dropped.
  std::vector<std::int64_t> particleOf(vertices.size(), kNone);
  for (const Triangle& tri : triangles) {
    for (const std::uint32_t v : tri) particleOf[v] = 0;
  }
  const std::int64_t stride = fill.columns + 1;
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    if (particleOf[v] == kNone) continue;
    particleOf[v] = static_cast<std::int64_t>(result.positions.size());
    const glm::dvec2 p = frame.toWorld(vertices[v].position);
    result.positions.push_back(glm::dvec3(p.x, spec.height, p.y));
    const std::int64_t node = vertices[v].node;
    // Columns and rows stay below 2^17 plus the margin (kMaxSpanCells).
    result.nodes.push_back(
        node == kNone ? kNoNode : glm::ivec2(static_cast<int>(node % stride), static_cast<int>(node / stride)));
  }
  result.triangles.reserve(triangles.size());
  for (const Triangle& tri : triangles) {
    result.triangles.push_back(glm::uvec3(static_cast<std::uint32_t>(particleOf[tri[0]]),
                                          static_cast<std::uint32_t>(particleOf[tri[1]]),
                                          static_cast<std::uint32_t>(particleOf[tri[2]])));
  }
  return result;
}

}  // namespace drape::mesh
