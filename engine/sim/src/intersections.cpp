#include "drape/sim/intersections.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "drape/sim/world.hpp"

namespace drape::sim {

namespace {

__extension__ typedef __int128 Wide;  // exact for the determinants below

constexpr double kGrid = 16777216.0;    // 2^24 grid points a metre
constexpr double kMaxCoordinate = 1e4;  // m: |x| 2^24 < 2^38, so a 3 x 3 determinant < 2^118

using Point = std::array<std::int64_t, 3>;

int sign(Wide x) { return (x > 0) - (x < 0); }

// Sign of the volume of the tetrahedron abcd: > 0 when d is on the side of abc's normal
// (b - a) x (c - a).
int orient3(const Point& a, const Point& b, const Point& c, const Point& d) {
  const Wide ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
  const Wide vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
  const Wide wx = d[0] - a[0], wy = d[1] - a[1], wz = d[2] - a[2];
  return sign(ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx));
}

// In the plane of a triangle, seen along the axis its normal is largest on: 2D points.
struct Plane2 {
  int u, v;  // the two axes kept
  int orient(const Point& a, const Point& b, const Point& c) const {
    return sign(static_cast<Wide>(b[u] - a[u]) * (c[v] - a[v]) - static_cast<Wide>(b[v] - a[v]) * (c[u] - a[u]));
  }
  // Whether c (collinear with ab) lies on the closed segment ab.
  bool onSegment(const Point& a, const Point& b, const Point& c) const {
    return std::min(a[u], b[u]) <= c[u] && c[u] <= std::max(a[u], b[u]) && std::min(a[v], b[v]) <= c[v] &&
           c[v] <= std::max(a[v], b[v]);
  }
  bool segmentsMeet(const Point& a, const Point& b, const Point& c, const Point& d) const {
    const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
    if (o1 * o2 < 0 && o3 * o4 < 0) return true;  // crossing
    return (o1 == 0 && onSegment(a, b, c)) || (o2 == 0 && onSegment(a, b, d)) || (o3 == 0 && onSegment(c, d, a)) ||
           (o4 == 0 && onSegment(c, d, b));
  }
  bool inside(const Point& p, const Point& a, const Point& b, const Point& c) const {
    const int o1 = orient(a, b, p), o2 = orient(b, c, p), o3 = orient(c, a, p);
    return !((o1 > 0 || o2 > 0 || o3 > 0) && (o1 < 0 || o2 < 0 || o3 < 0));
  }
};

struct Triangle {
  Point p[3];
  std::array<std::uint32_t, 3> particle;  // world-wide: which corners two triangles share
  Point lower, upper;                     // bounding box
  Plane2 plane;                           // for tests in its own plane
};

// Closed segment ab against closed triangle t.
bool segmentHits(const Point& a, const Point& b, const Triangle& t) {
  const int sa = orient3(t.p[0], t.p[1], t.p[2], a), sb = orient3(t.p[0], t.p[1], t.p[2], b);
  if (sa == sb && sa != 0) return false;  // both on one side
  if (sa == 0 && sb == 0) {               // in its plane
    const Plane2& q = t.plane;
    return q.inside(a, t.p[0], t.p[1], t.p[2]) || q.inside(b, t.p[0], t.p[1], t.p[2]) ||
           q.segmentsMeet(a, b, t.p[0], t.p[1]) || q.segmentsMeet(a, b, t.p[1], t.p[2]) ||
           q.segmentsMeet(a, b, t.p[2], t.p[0]);
  }
  // The segment meets the plane at one point: on the triangle when the line ab passes by its three
  // edges on one side (a zero: through an edge or a corner).
  const int o1 = orient3(a, b, t.p[0], t.p[1]), o2 = orient3(a, b, t.p[1], t.p[2]), o3 = orient3(a, b, t.p[2], t.p[0]);
  return !((o1 > 0 || o2 > 0 || o3 > 0) && (o1 < 0 || o2 < 0 || o3 < 0));
}

bool allOnOneSide(const Triangle& plane, const Triangle& t) {
  const int s0 = orient3(plane.p[0], plane.p[1], plane.p[2], t.p[0]);
  const int s1 = orient3(plane.p[0], plane.p[1], plane.p[2], t.p[1]);
  const int s2 = orient3(plane.p[0], plane.p[1], plane.p[2], t.p[2]);
  return s0 != 0 && s0 == s1 && s1 == s2;
}

bool intersect(const Triangle& s, const Triangle& t) {
  int shared = 0, sharedInS = -1, sharedInT = -1;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (s.particle[i] == t.particle[j]) {
        ++shared;
        sharedInS = i;
        sharedInT = j;
      }
    }
  }
  if (shared >= 2) return false;  // neighbours across an edge
  if (allOnOneSide(s, t) || allOnOneSide(t, s)) return false;
  if (shared == 1) {
    // They meet at the shared corner; they pass through each other where the edge of one opposite
    // it crosses the other.
    const int i = sharedInS, j = sharedInT;
    return segmentHits(s.p[(i + 1) % 3], s.p[(i + 2) % 3], t) || segmentHits(t.p[(j + 1) % 3], t.p[(j + 2) % 3], s);
  }
  // Two closed triangles meet where an edge of one meets the other: the ends of the segment they
  // share (or of the region, in one plane) lie on their edges.
  for (int k = 0; k < 3; ++k) {
    if (segmentHits(s.p[k], s.p[(k + 1) % 3], t) || segmentHits(t.p[k], t.p[(k + 1) % 3], s)) return true;
  }
  return false;
}

}  // namespace

IntersectionCount countIntersections(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& triangles) {
  IntersectionCount count;
  std::vector<Triangle> kept;
  kept.reserve(triangles.size());
  for (const glm::uvec3& corners : triangles) {
    Triangle t;
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      const Vec3 x = positions[corners[k]];
      for (int axis = 0; axis < 3; ++axis) {
        ok = ok && std::abs(x[axis]) <= kMaxCoordinate;  // false for NaN too
        t.p[k][axis] = ok ? static_cast<std::int64_t>(std::llround(x[axis] * kGrid)) : 0;
      }
      t.particle[k] = corners[k];
    }
    // Its normal, exactly: a triangle of no area on the grid has no plane to be crossed through.
    const Wide e1[3] = {t.p[1][0] - t.p[0][0], t.p[1][1] - t.p[0][1], t.p[1][2] - t.p[0][2]};
    const Wide e2[3] = {t.p[2][0] - t.p[0][0], t.p[2][1] - t.p[0][1], t.p[2][2] - t.p[0][2]};
    const Wide n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    if (!ok || (n[0] == 0 && n[1] == 0 && n[2] == 0)) {
      ++count.skipped;
      continue;
    }
    const auto magnitude = [](Wide x) { return x < 0 ? -x : x; };
    const int drop = magnitude(n[0]) >= magnitude(n[1]) && magnitude(n[0]) >= magnitude(n[2]) ? 0
                     : magnitude(n[1]) >= magnitude(n[2])                                     ? 1
                                                                                              : 2;
    t.plane = {(drop + 1) % 3, (drop + 2) % 3};
    for (int axis = 0; axis < 3; ++axis) {
      t.lower[axis] = std::min({t.p[0][axis], t.p[1][axis], t.p[2][axis]});
      t.upper[axis] = std::max({t.p[0][axis], t.p[1][axis], t.p[2][axis]});
    }
    kept.push_back(t);
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
        if (overlap && corner == entries[first].cell && intersect(s, t)) ++count.pairs;
      }
    }
    first = last;
  }
  return count;
}

IntersectionCount countIntersections(const World& world) {
  std::vector<Vec3> positions;
  std::vector<glm::uvec3> triangles;
  for (const Cloth& cloth : world.cloths()) {
    const auto base = static_cast<unsigned>(positions.size());
    positions.insert(positions.end(), cloth.state.position.begin(), cloth.state.position.end());
    for (const glm::uvec3& t : cloth.rest.triangles) triangles.push_back(t + base);
  }
  return countIntersections(positions, triangles);
}

}  // namespace drape::sim
