// The outline mesher's steps 1 to 3 (drape/mesh/outline.hpp): from a stroke to a simple loop; internal.
#pragma once

#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "drape/mesh/outline.hpp"
#include "exact.hpp"

namespace drape::mesh::detail {

// The integer frame: point (x, z) in metres is origin + unit * (u, w).
struct Frame {
  glm::dvec2 origin{0.0};
  double unit = 1.0;  // m per integer unit
  glm::dvec2 toWorld(const glm::dvec2& p) const { return origin + unit * p; }
  glm::dvec2 toWorld(const Point& p) const {
    return toWorld(glm::dvec2(static_cast<double>(p.x), static_cast<double>(p.z)));
  }
};

struct Loop {
  std::vector<Point> points;  // simple, counter-clockwise seen from +y
  bool tookLargest = false;
};

// "outline encloses <area> m^2, less than one cell at spacing <spacing> m"
std::string tooSmall(double area, double spacing);

// Rejects what cannot be an outline before anything is converted: spacing, height and points not
// finite, fewer than 3 distinct points, collinear points.
void checkStroke(const OutlineSpec& spec);

// Steps 1 to 3: clean, untangle, orient; then the size checks (too small, too many particles),
// before anything big is allocated. The loop's points are in the integer frame.
Loop loopFromStroke(const OutlineSpec& spec, const Frame& frame);

}  // namespace drape::mesh::detail
