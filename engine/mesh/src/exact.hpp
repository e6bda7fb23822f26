// Exact geometry on integers, for the outline mesher (loop.cpp, fill.cpp, outline.cpp); internal.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace drape::mesh::detail {

// Clipping a lattice against a polygon asks the same question many ways (is this node inside? does this edge cross
// that segment? in which order along the edge?). Answered in floating point, near-degenerate cases can answer two of
// them inconsistently and tear the mesh. So the loop lives on an integer grid and every such question is decided
// exactly, in 128-bit arithmetic. Coordinates stay below 2^30, so an orientation is below 2^61 and the comparison of
// two ratios of orientations below 2^124.

using Coord = std::int64_t;
__extension__ typedef __int128 Wide;  // GCC and Clang; __extension__ keeps -Wpedantic quiet

constexpr Coord kUnitsPerSpacing = 4096;  // the lattice spacing in integer units

struct Point {
  Coord x = 0;
  Coord z = 0;
  friend bool operator==(const Point&, const Point&) = default;
};

// Twice the signed area of p, q, r: positive when counter-clockwise seen from +y (cross(q - p, r - p).y > 0).
inline Wide orient(const Point& p, const Point& q, const Point& r) {
  return static_cast<Wide>(q.z - p.z) * (r.x - p.x) - static_cast<Wide>(q.x - p.x) * (r.z - p.z);
}

inline Wide dot(const Point& a, const Point& b, const Point& c, const Point& d) {  // (b - a) . (d - c)
  return static_cast<Wide>(b.x - a.x) * (d.x - c.x) + static_cast<Wide>(b.z - a.z) * (d.z - c.z);
}

inline int sign(Wide value) { return value > 0 ? 1 : (value < 0 ? -1 : 0); }

inline Coord floorDiv(Coord a, Coord b) {
  Coord q = a / b;
  if (a % b != 0 && ((a < 0) != (b < 0))) --q;
  return q;
}

inline Wide ceilDiv(Wide a, Wide b) {  // b > 0
  Wide q = a / b;
  if (a % b != 0 && a > 0) ++q;
  return q;
}

// A number num / den with den > 0, compared exactly.
struct Ratio {
  Wide numerator = 0;
  Wide denominator = 1;
};

inline Ratio makeRatio(Wide numerator, Wide denominator) {
  if (denominator < 0) return {-numerator, -denominator};
  return {numerator, denominator};
}

inline bool less(const Ratio& a, const Ratio& b) { return a.numerator * b.denominator < b.numerator * a.denominator; }
inline bool equal(const Ratio& a, const Ratio& b) { return a.numerator * b.denominator == b.numerator * a.denominator; }
inline double toDouble(const Ratio& r) { return static_cast<double>(r.numerator) / static_cast<double>(r.denominator); }

inline double length(const Point& a, const Point& b) {
  return std::hypot(static_cast<double>(b.x - a.x), static_cast<double>(b.z - a.z));
}

// Twice the signed area of a closed loop.
inline Wide twiceArea(const std::vector<Point>& loop) {
  Wide sum = 0;
  for (std::size_t i = 1; i + 1 < loop.size(); ++i) sum += orient(loop[0], loop[i], loop[i + 1]);
  return sum;
}

// Calls visit(column, row) for every cell of size `cell` that the segment a-b touches, and a few neighbours: the
// caller tests exactly, this only has to miss nothing.
template <class Visit>
inline void forEachCellAlong(Point a, Point b, Coord cell, Visit&& visit) {
  const bool alongX = std::llabs(b.x - a.x) >= std::llabs(b.z - a.z);
  const auto major = [&](const Point& p) { return alongX ? p.x : p.z; };
  const auto minor = [&](const Point& p) { return alongX ? p.z : p.x; };
  if (major(a) > major(b)) std::swap(a, b);
  const Coord u0 = major(a), u1 = major(b), v0 = minor(a), v1 = minor(b);
  const double slope = u1 > u0 ? static_cast<double>(v1 - v0) / static_cast<double>(u1 - u0) : 0.0;
  for (Coord column = floorDiv(u0, cell); column <= floorDiv(u1, cell); ++column) {
    const Coord lo = std::max(u0, column * cell), hi = std::min(u1, (column + 1) * cell);
    const double va = static_cast<double>(v0) + slope * static_cast<double>(lo - u0);
    const double vb = static_cast<double>(v0) + slope * static_cast<double>(hi - u0);
    // One unit of slack each side absorbs the rounding of va and vb.
    const Coord r0 = floorDiv(static_cast<Coord>(std::floor(std::min(va, vb))) - 1, cell);
    const Coord r1 = floorDiv(static_cast<Coord>(std::ceil(std::max(va, vb))) + 1, cell);
    for (Coord row = r0; row <= r1; ++row) {
      if (alongX) {
        visit(column, row);
      } else {
        visit(row, column);
      }
    }
  }
}

// Segments filed by the cells they pass through, to find the ones near another segment.
class SegmentGrid {
 public:
  explicit SegmentGrid(Coord cell) : cell_(cell) {}

  void insert(std::uint32_t id, const Point& a, const Point& b) {
    forEachCellAlong(a, b, cell_, [&](Coord x, Coord z) { buckets_[key(x, z)].push_back(id); });
  }

  // Calls visit(id) for every segment filed in a cell a-b passes through; an id may come more than once. Ids for
  // which isLive(id) is false are dropped from the grid on the way, so dead segments cost once.
  template <class IsLive, class Visit>
  void forEachNear(const Point& a, const Point& b, IsLive&& isLive, Visit&& visit) {
    forEachCellAlong(a, b, cell_, [&](Coord x, Coord z) {
      const auto found = buckets_.find(key(x, z));
      if (found == buckets_.end()) return;
      std::vector<std::uint32_t>& ids = found->second;
      for (std::size_t n = 0; n < ids.size();) {
        if (!isLive(ids[n])) {
          ids[n] = ids.back();
          ids.pop_back();
          continue;
        }
        visit(ids[n]);
        ++n;
      }
    });
  }

 private:
  static std::int64_t key(Coord x, Coord z) { return x * (std::int64_t{1} << 32) + z; }  // z in [-1, 2^31)

  Coord cell_;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> buckets_;
};

// Ids seen during one query, without clearing a set each time.
class Stamps {
 public:
  void next(std::size_t size) {
    if (seen_.size() < size) seen_.resize(size, 0);
    if (++now_ == 0) {  // wrapped: forget everything
      std::fill(seen_.begin(), seen_.end(), 0);
      now_ = 1;
    }
  }
  bool firstTime(std::uint32_t id) {
    if (seen_.size() <= id) seen_.resize(std::size_t{id} + 1, 0);
    if (seen_[id] == now_) return false;
    seen_[id] = now_;
    return true;
  }

 private:
  std::vector<std::uint32_t> seen_;
  std::uint32_t now_ = 0;
};

// Where along e->q (as a fraction) the closed segment e-q first meets the closed segment u-v, if it does.
inline std::optional<Ratio> firstContact(const Point& e, const Point& q, const Point& u, const Point& v) {
  const Wide o1 = orient(u, v, e), o2 = orient(u, v, q);
  if ((o1 > 0 && o2 > 0) || (o1 < 0 && o2 < 0)) return std::nullopt;
  const Wide o3 = orient(e, q, u), o4 = orient(e, q, v);
  if ((o3 > 0 && o4 > 0) || (o3 < 0 && o4 < 0)) return std::nullopt;
  if (o1 != 0 || o2 != 0) return makeRatio(o1, o1 - o2);
  // All four on one line: the overlap, if any, starts at the nearer of e, u and v.
  const Wide length2 = dot(e, q, e, q);
  const Wide tu = dot(e, u, e, q), tv = dot(e, v, e, q);
  const Wide lo = std::min(tu, tv), hi = std::max(tu, tv);
  if (hi < 0 || lo > length2) return std::nullopt;
  return makeRatio(std::max(lo, Wide{0}), length2);
}

inline std::string number(long double value) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.3Lg", value);
  return buffer;
}

[[noreturn]] inline void fail(const std::string& message) { throw std::invalid_argument(message); }

}  // namespace drape::mesh::detail
