// The exact triangle-triangle test behind countIntersections (intersections.hpp), for the engine's
// own use: self-contact's fail-safe asks it whether a step made two triangles pass through each
// other, with the same answer the counter would give.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

#include "drape/sim/types.hpp"

namespace drape::sim::exact {

__extension__ typedef __int128 Wide;  // exact for the determinants below

inline constexpr double kGrid = 16777216.0;    // 2^24 grid points a metre
inline constexpr double kMaxCoordinate = 1e4;  // m: |x| 2^24 < 2^38, so a 3 x 3 determinant < 2^118

using Point = std::array<std::int64_t, 3>;

inline int sign(Wide x) { return (x > 0) - (x < 0); }

// Sign of the volume of the tetrahedron abcd: > 0 when d is on the side of abc's normal
// (b - a) x (c - a).
inline int orient3(const Point& a, const Point& b, const Point& c, const Point& d) {
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
inline bool segmentHits(const Point& a, const Point& b, const Triangle& t) {
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

inline bool allOnOneSide(const Triangle& plane, const Triangle& t) {
  const int s0 = orient3(plane.p[0], plane.p[1], plane.p[2], t.p[0]);
  const int s1 = orient3(plane.p[0], plane.p[1], plane.p[2], t.p[1]);
  const int s2 = orient3(plane.p[0], plane.p[1], plane.p[2], t.p[2]);
  return s0 != 0 && s0 == s1 && s1 == s2;
}

inline bool intersect(const Triangle& s, const Triangle& t) {
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
  if (shared == 3) return false;  // one triangle twice
  if (shared == 2) {
    // Neighbours across an edge ab meet beyond it only folded flat onto each other: their other
    // corners c and d in one plane with a and b, and on one side of ab there.
    int c = 0, d = 0;
    for (int i = 0; i < 3; ++i) {
      if (s.particle[i] != t.particle[0] && s.particle[i] != t.particle[1] && s.particle[i] != t.particle[2]) c = i;
      if (t.particle[i] != s.particle[0] && t.particle[i] != s.particle[1] && t.particle[i] != s.particle[2]) d = i;
    }
    const Point& a = s.p[(c + 1) % 3];
    const Point& b = s.p[(c + 2) % 3];
    if (orient3(s.p[0], s.p[1], s.p[2], t.p[d]) != 0) return false;
    return s.plane.orient(a, b, s.p[c]) == s.plane.orient(a, b, t.p[d]);
  }
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

// A triangle over three positions (m), rounded to the grid; nothing if a corner is not finite or
// beyond 10^4 m, or the triangle has no area on the grid. `ids` tell which corners two triangles share.
std::optional<Triangle> makeTriangle(const Vec3& a, const Vec3& b, const Vec3& c,
                                     const std::array<std::uint32_t, 3>& ids);

}  // namespace drape::sim::exact
