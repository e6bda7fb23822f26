#include "drape/sim/intersections.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "drape/sim/world.hpp"
#include "collision/exact_triangles.hpp"

namespace drape::sim {

using exact::makeTriangle;
using exact::Triangle;

namespace exact {

std::optional<Triangle> makeTriangle(const Vec3& a, const Vec3& b, const Vec3& c,
                                     const std::array<std::uint32_t, 3>& ids) {
  Triangle t;
  bool ok = true;
  const Vec3* corner[3] = {&a, &b, &c};
  for (int k = 0; k < 3; ++k) {
    const Vec3 x = *corner[k];
    for (int axis = 0; axis < 3; ++axis) {
      ok = ok && std::abs(x[axis]) <= kMaxCoordinate;  // false for NaN too
      t.p[k][axis] = ok ? static_cast<std::int64_t>(std::llround(x[axis] * kGrid)) : 0;
    }
    t.particle[k] = ids[static_cast<std::size_t>(k)];
  }
  // Its normal, exactly: a triangle of no area on the grid has no plane to be crossed through.
  const Wide e1[3] = {t.p[1][0] - t.p[0][0], t.p[1][1] - t.p[0][1], t.p[1][2] - t.p[0][2]};
  const Wide e2[3] = {t.p[2][0] - t.p[0][0], t.p[2][1] - t.p[0][1], t.p[2][2] - t.p[0][2]};
  const Wide n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  if (!ok || (n[0] == 0 && n[1] == 0 && n[2] == 0)) return std::nullopt;
  const auto magnitude = [](Wide x) { return x < 0 ? -x : x; };
  const int drop = magnitude(n[0]) >= magnitude(n[1]) && magnitude(n[0]) >= magnitude(n[2]) ? 0
                   : magnitude(n[1]) >= magnitude(n[2])                                     ? 1
                                                                                            : 2;
  t.plane = {(drop + 1) % 3, (drop + 2) % 3};
  for (int axis = 0; axis < 3; ++axis) {
    t.lower[axis] = std::min({t.p[0][axis], t.p[1][axis], t.p[2][axis]});
    t.upper[axis] = std::max({t.p[0][axis], t.p[1][axis], t.p[2][axis]});
  }
  return t;
}

}  // namespace exact

IntersectionCount countIntersections(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& triangles) {
  return countIntersections(positions, triangles, triangles);
}

IntersectionCount countIntersections(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& triangles,
                                     const std::vector<glm::uvec3>& shared) {
  IntersectionCount count;
  std::vector<Triangle> kept;
  kept.reserve(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const glm::uvec3& corners = triangles[i];
    const std::optional<Triangle> t = makeTriangle(positions[corners[0]], positions[corners[1]], positions[corners[2]],
                                                   {shared[i][0], shared[i][1], shared[i][2]});
    if (t) {
      kept.push_back(*t);
    } else {
      ++count.skipped;
    }
  }
  if (kept.size() < 2) return count;

  // Broad phase: a grid of cells about a triangle wide; a pair whose boxes overlap is tested once,
  // in the cell that holds the lowest corner of the overlap.
  double extent = 0.0;
  for (const Triangle& t : kept) {
    extent +=
        static_cast<double>(std::max({t.upper[0] - t.lower[0], t.upper[1] - t.lower[1], t.upper[2] - t.lower[2]}));
  }
  const std::int64_t cell =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(extent / static_cast<double>(kept.size())));
  const auto cellOf = [&](std::int64_t x) { return x >= 0 ? x / cell : -((-x + cell - 1) / cell); };
  struct Entry {
    std::array<std::int64_t, 3> cell;
    std::uint32_t triangle;
    bool operator<(const Entry& o) const { return cell < o.cell || (cell == o.cell && triangle < o.triangle); }
  };
  std::vector<Entry> entries;
  for (std::uint32_t i = 0; i < kept.size(); ++i) {
    const Triangle& t = kept[i];
    for (std::int64_t z = cellOf(t.lower[2]); z <= cellOf(t.upper[2]); ++z) {
      for (std::int64_t y = cellOf(t.lower[1]); y <= cellOf(t.upper[1]); ++y) {
        for (std::int64_t x = cellOf(t.lower[0]); x <= cellOf(t.upper[0]); ++x) entries.push_back({{x, y, z}, i});
      }
    }
  }
  std::sort(entries.begin(), entries.end());
  for (std::size_t first = 0; first < entries.size();) {
    std::size_t last = first;
    while (last < entries.size() && entries[last].cell == entries[first].cell) ++last;
    for (std::size_t a = first; a < last; ++a) {
      const Triangle& s = kept[entries[a].triangle];
      for (std::size_t b = a + 1; b < last; ++b) {
        const Triangle& t = kept[entries[b].triangle];
        bool overlap = true;
        std::array<std::int64_t, 3> corner{};
        for (int axis = 0; axis < 3; ++axis) {
          overlap = overlap && s.lower[axis] <= t.upper[axis] && t.lower[axis] <= s.upper[axis];
          corner[axis] = cellOf(std::max(s.lower[axis], t.lower[axis]));
        }
        if (overlap && corner == entries[first].cell && exact::intersect(s, t)) ++count.pairs;
      }
    }
    first = last;
  }
  return count;
}

IntersectionCount countIntersections(const World& world) {
  std::vector<Vec3> positions;
  std::vector<glm::uvec3> triangles, shared;
  for (const Cloth& cloth : world.cloths()) {
    const auto base = static_cast<unsigned>(positions.size());
    positions.insert(positions.end(), cloth.state.position.begin(), cloth.state.position.end());
    // Particles of one cloth at one point of the grid are one corner: the copies a tear or a cut
    // made of a particle, before the seam opens, join the triangles on its two sides as they were
    // joined before it.
    std::vector<std::uint32_t> canonical(cloth.state.position.size());
    if (cloth.topology.built) {
      std::vector<std::pair<std::array<std::int64_t, 3>, std::uint32_t>> points;
      points.reserve(canonical.size());
      for (std::uint32_t i = 0; i < canonical.size(); ++i) {
        const Vec3 x = cloth.state.position[i];
        std::array<std::int64_t, 3> p{};
        for (int axis = 0; axis < 3; ++axis) {
          p[static_cast<std::size_t>(axis)] =
              std::abs(x[axis]) <= exact::kMaxCoordinate ? std::llround(x[axis] * exact::kGrid) : 0;
        }
        points.push_back({p, i});
      }
      std::sort(points.begin(), points.end());
      for (std::size_t k = 0; k < points.size(); ++k) {
        canonical[points[k].second] =
            k > 0 && points[k].first == points[k - 1].first ? canonical[points[k - 1].second] : points[k].second;
      }
    } else {
      for (std::uint32_t i = 0; i < canonical.size(); ++i) canonical[i] = i;
    }
    for (const glm::uvec3& t : cloth.rest.triangles) {
      // The corners' positions stay their own; only which corners two triangles share changes.
      triangles.push_back(t + base);
      shared.push_back(glm::uvec3(canonical[t[0]], canonical[t[1]], canonical[t[2]]) + base);
    }
  }
  return countIntersections(positions, triangles, shared);
}

}  // namespace drape::sim
