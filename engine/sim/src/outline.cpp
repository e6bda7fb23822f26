#include "drape/sim/outline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <queue>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/settings.hpp"

namespace drape::sim {
namespace {

// ----------------------------------------------------------------------------------------------------------------
// Exact geometry on integers.
//
// Clipping a lattice against a polygon asks the same question many ways (is this node inside? does this edge cross
// that segment? in which order along the edge?). Answered in floating point, near-degenerate cases can answer two of
// them inconsistently and tear the mesh. So the loop lives on an integer grid and every such question is decided
// exactly, in 128-bit arithmetic. Coordinates stay below 2^30, so an orientation is below 2^61 and the comparison of
// two ratios of orientations below 2^124.

using Coord = std::int64_t;
__extension__ typedef __int128 Wide;  // GCC and Clang; __extension__ keeps -Wpedantic quiet

constexpr Coord kUnitsPerSpacing = 4096;    // the lattice spacing in integer units
constexpr double kMinSpacing = 1e-9;        // m
constexpr Coord kMarginCells = 2;           // empty lattice cells around the stroke
constexpr double kMaxSpanCells = 131072.0;  // 2^17: keeps coordinates below 2^30
// Segment pairs the untangling may test, and steps the fill may take beyond its linear work, before the outline is
// called too intricate (each about half a second). Only strokes with far more detail than the spacing get there.
constexpr std::uint64_t kMaxIntersectionTests = 50'000'000;
constexpr std::uint64_t kMaxFillWork = 200'000'000;
constexpr const char* kTooIntricate = "outline is too intricate to untangle (far more detail than the spacing)";

// Collapse thresholds, in spacings: a node moves onto the loop when closer than kMoveDistance to a boundary
// particle; boundary particles merge along the loop when closer than kMergeDistance.
constexpr double kMoveDistance = 0.5;
constexpr double kMergeDistance = 0.4;
// Triangle quality (1 for equilateral, 0.87 for the lattice's half cell) that counts as good: a collapse may not
// turn a good triangle poor, and poor ones are what edge flips work on.
constexpr double kQualityFloor = 0.25;
// How far along the loop (in spacings) a node landing on it may sweep up loop points that would flatten.
constexpr double kSweepDistance = 0.75;
// A boundary particle takes the lattice position of an outside node closer than this (in spacings).
constexpr double kClaimDistance = 0.5;

struct Point {
  Coord x = 0;
  Coord z = 0;
  friend bool operator==(const Point&, const Point&) = default;
};

// Twice the signed area of p, q, r: positive when counter-clockwise seen from +y (cross(q - p, r - p).y > 0).
Wide orient(const Point& p, const Point& q, const Point& r) {
  return static_cast<Wide>(q.z - p.z) * (r.x - p.x) - static_cast<Wide>(q.x - p.x) * (r.z - p.z);
}

Wide dot(const Point& a, const Point& b, const Point& c, const Point& d) {  // (b - a) . (d - c)
  return static_cast<Wide>(b.x - a.x) * (d.x - c.x) + static_cast<Wide>(b.z - a.z) * (d.z - c.z);
}

int sign(Wide value) { return value > 0 ? 1 : (value < 0 ? -1 : 0); }

Coord floorDiv(Coord a, Coord b) {
  Coord q = a / b;
  if (a % b != 0 && ((a < 0) != (b < 0))) --q;
  return q;
}

Wide ceilDiv(Wide a, Wide b) {  // b > 0
  Wide q = a / b;
  if (a % b != 0 && a > 0) ++q;
  return q;
}

// A number num / den with den > 0, compared exactly.
struct Ratio {
  Wide numerator = 0;
  Wide denominator = 1;
};

Ratio makeRatio(Wide numerator, Wide denominator) {
  if (denominator < 0) return {-numerator, -denominator};
  return {numerator, denominator};
}

bool less(const Ratio& a, const Ratio& b) { return a.numerator * b.denominator < b.numerator * a.denominator; }
bool equal(const Ratio& a, const Ratio& b) { return a.numerator * b.denominator == b.numerator * a.denominator; }
double toDouble(const Ratio& r) { return static_cast<double>(r.numerator) / static_cast<double>(r.denominator); }

double length(const Point& a, const Point& b) {
  return std::hypot(static_cast<double>(b.x - a.x), static_cast<double>(b.z - a.z));
}

// Twice the signed area of a closed loop.
Wide twiceArea(const std::vector<Point>& loop) {
  Wide sum = 0;
  for (std::size_t i = 1; i + 1 < loop.size(); ++i) sum += orient(loop[0], loop[i], loop[i + 1]);
  return sum;
}

// Calls visit(column, row) for every cell of size `cell` that the segment a-b touches, and a few neighbours: the
// caller tests exactly, this only has to miss nothing.
template <class Visit>
void forEachCellAlong(Point a, Point b, Coord cell, Visit&& visit) {
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
std::optional<Ratio> firstContact(const Point& e, const Point& q, const Point& u, const Point& v) {
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

std::string number(long double value) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.3Lg", value);
  return buffer;
}

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

// ----------------------------------------------------------------------------------------------------------------
// From stroke to loop.

// The integer frame: point (x, z) in metres is origin + unit * (u, w).
struct Frame {
  glm::dvec2 origin{0.0};
  double unit = 1.0;  // m per integer unit
  glm::dvec2 toWorld(const glm::dvec2& p) const { return origin + unit * p; }
  glm::dvec2 toWorld(const Point& p) const {
    return toWorld(glm::dvec2(static_cast<double>(p.x), static_cast<double>(p.z)));
  }
};

// Nearest integer that is 1 modulo 4. Loop points live on that sub-grid and lattice nodes on multiples of
// kUnitsPerSpacing, so no loop point ever lies on a lattice line x = iK, z = jK or on a lattice diagonal x + z = kK.
Coord snapToLoopGrid(double value) {
  const double quarter = std::floor((value - 1.0) / 4.0 + 0.5);
  return static_cast<Coord>(quarter) * 4 + 1;
}

Point snapToLoopGrid(const Point& e, const Point& q, const Ratio& t) {
  const double f = toDouble(t);
  return {snapToLoopGrid(static_cast<double>(e.x) + f * static_cast<double>(q.x - e.x)),
          snapToLoopGrid(static_cast<double>(e.z) + f * static_cast<double>(q.z - e.z))};
}

// Douglas-Peucker on an open polyline: keeps the ends and every point that is farther than `tolerance` from the
// simplified line. Its worst case is quadratic (a comb whose every split peels off one tooth), so it scans at most
// about 20 points per point; ranges still pending then keep all their points, which are already spacing/4 apart.
std::vector<Point> simplify(const std::vector<Point>& points, double tolerance) {
  if (points.size() < 3) return points;
  std::vector<char> keep(points.size(), 0);
  keep.front() = keep.back() = 1;
  std::vector<std::pair<std::size_t, std::size_t>> stack{{0, points.size() - 1}};
  std::size_t budget = 20 * points.size() + 1'000'000;
  while (!stack.empty()) {
    const auto [first, last] = stack.back();
    stack.pop_back();
    if (last <= first + 1) continue;
    if (last - first > budget) {
      std::fill(keep.begin() + static_cast<std::ptrdiff_t>(first), keep.begin() + static_cast<std::ptrdiff_t>(last), 1);
      continue;
    }
    budget -= last - first;
    const glm::dvec2 a(static_cast<double>(points[first].x), static_cast<double>(points[first].z));
    const glm::dvec2 b(static_cast<double>(points[last].x), static_cast<double>(points[last].z));
    const glm::dvec2 ab = b - a;
    const double ab2 = glm::dot(ab, ab);
    double farthest = -1.0;
    std::size_t at = first;
    for (std::size_t i = first + 1; i < last; ++i) {
      const glm::dvec2 p(static_cast<double>(points[i].x), static_cast<double>(points[i].z));
      // Distance to the segment, not the line, so that a stroke doubling back is not flattened.
      const double t = ab2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / ab2, 0.0, 1.0) : 0.0;
      const double d = glm::length(p - (a + t * ab));
      if (d > farthest) {
        farthest = d;
        at = i;
      }
    }
    if (farthest > tolerance) {
      keep[at] = 1;
      stack.push_back({first, at});
      stack.push_back({at, last});
    }
  }
  std::vector<Point> kept;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (keep[i]) kept.push_back(points[i]);
  }
  return kept;
}

// A loop's points linked in a ring, from which points are removed one at a time.
struct Ring {
  explicit Ring(std::size_t n) : next(n), previous(n), alive(n, 1), count(n) {
    for (std::size_t i = 0; i < n; ++i) {
      next[i] = (i + 1) % n;
      previous[i] = (i + n - 1) % n;
    }
  }
  // Takes point i out: its neighbours join.
  void unlink(std::size_t i) {
    const std::size_t a = previous[i], c = next[i];
    next[a] = c;
    previous[c] = a;
    alive[i] = 0;
    --count;
  }
  // The points still in, in loop order.
  std::vector<Point> kept(const std::vector<Point>& loop) const {
    std::vector<Point> result;
    for (std::size_t i = 0; i < loop.size(); ++i) {
      if (alive[i]) result.push_back(loop[i]);
    }
    return result;
  }
  std::vector<std::size_t> next, previous;
  std::vector<char> alive;
  std::size_t count;
};

// Removes repeated points and points on a straight line between (or folding back onto) their neighbours.
std::vector<Point> dropStraightPoints(const std::vector<Point>& loop) {
  const std::size_t n = loop.size();
  Ring ring(n);
  std::vector<std::size_t> work(n);
  for (std::size_t i = 0; i < n; ++i) work[i] = n - 1 - i;
  while (!work.empty() && ring.count >= 3) {
    const std::size_t i = work.back();
    work.pop_back();
    if (!ring.alive[i]) continue;
    const std::size_t p = ring.previous[i], q = ring.next[i];
    if (!(loop[i] == loop[p]) && orient(loop[p], loop[i], loop[q]) != 0) continue;
    ring.unlink(i);
    work.push_back(q);
    work.push_back(p);
  }
  return ring.count >= 3 ? ring.kept(loop) : std::vector<Point>{};
}

struct Untangled {
  std::vector<Point> loop;  // the largest loop cut off, as it was walked
  int loopsWithArea = 0;
};

// Walks the closed stroke and cuts off a loop whenever it meets its own path (see the header); keeps the largest.
Untangled untangle(const std::vector<Point>& stroke, std::uint64_t& tests) {
  double totalLength = 0.0;
  for (std::size_t i = 0; i < stroke.size(); ++i) totalLength += length(stroke[i], stroke[(i + 1) % stroke.size()]);
  const Coord cell =
      std::max<Coord>(kUnitsPerSpacing / 4, static_cast<Coord>(totalLength / static_cast<double>(stroke.size())));
  SegmentGrid grid(cell);
  Stamps stamps;
  std::vector<Point> path;                  // the simple path walked so far
  std::vector<std::uint32_t> pathSegment;   // id of the segment path[k] - path[k + 1]
  std::vector<std::uint32_t> segmentIndex;  // id -> k
  std::vector<std::pair<Point, Point>> segmentEnds;
  Untangled result;
  Wide largest = 0;

  const auto isLive = [&](std::uint32_t id) {
    const std::uint32_t k = segmentIndex[id];
    return k < pathSegment.size() && pathSegment[k] == id;
  };
  const auto push = [&](const Point& p) {
    if (!path.empty()) {
      const auto id = static_cast<std::uint32_t>(segmentEnds.size());
      segmentEnds.push_back({path.back(), p});
      segmentIndex.push_back(static_cast<std::uint32_t>(pathSegment.size()));
      pathSegment.push_back(id);
      grid.insert(id, path.back(), p);
    }
    path.push_back(p);
  };
  const auto pop = [&] {
    path.pop_back();
    if (!pathSegment.empty()) pathSegment.pop_back();
  };
  const auto record = [&](std::vector<Point> loop) {
    loop = dropStraightPoints(loop);
    if (loop.size() < 3) return;
    Wide area = twiceArea(loop);
    if (area < 0) area = -area;
    if (area == 0) return;
    ++result.loopsWithArea;
    if (area > largest) {
      largest = area;
      result.loop = std::move(loop);
    }
  };
  // Extends the path to q, cutting off every loop closed on the way.
  const auto walkTo = [&](const Point& q, bool closing) {
    for (;;) {
      const Point e = path.back();
      if (e == q) return;
      if (path.size() >= 2) {
        const Point& p = path[path.size() - 2];
        if (orient(p, e, q) == 0 && dot(e, q, e, p) > 0) {  // doubling back along the last segment
          pop();
          continue;
        }
      }
      std::optional<Ratio> first;
      std::size_t firstIndex = 0;
      stamps.next(segmentEnds.size());
      grid.forEachNear(e, q, isLive, [&](std::uint32_t id) {
        if (++tests > kMaxIntersectionTests) fail(kTooIntricate);
        if (!stamps.firstTime(id)) return;
        const std::size_t k = segmentIndex[id];
        if (k + 2 == path.size()) return;  // the last segment, which ends at e
        const std::optional<Ratio> t = firstContact(e, q, segmentEnds[id].first, segmentEnds[id].second);
        if (!t) return;
        // The closing segment ends where the path began: that is the loop closing, not a crossing.
        if (closing && k == 0 && t->numerator == t->denominator) return;
        if (!first || less(*t, *first) || (equal(*t, *first) && k > firstIndex)) {
          first = t;
          firstIndex = k;
        }
      });
      if (!first) {
        push(q);
        return;
      }
      const Point x = snapToLoopGrid(e, q, *first);
      std::vector<Point> loop{x};
      loop.insert(loop.end(), path.begin() + static_cast<std::ptrdiff_t>(firstIndex) + 1, path.end());
      record(std::move(loop));
      while (path.size() > firstIndex + 1) pop();
      if (!(x == path.back())) push(x);
    }
  };

  push(stroke[0]);
  for (std::size_t i = 1; i < stroke.size(); ++i) walkTo(stroke[i], false);
  walkTo(stroke[0], true);
  record(path);
  return result;
}

bool isSimple(const std::vector<Point>& loop, std::uint64_t& tests) {
  const std::size_t n = loop.size();
  if (n < 3) return false;
  SegmentGrid grid(kUnitsPerSpacing);
  for (std::size_t i = 0; i < n; ++i) grid.insert(static_cast<std::uint32_t>(i), loop[i], loop[(i + 1) % n]);
  Stamps stamps;
  bool simple = true;
  for (std::size_t i = 0; i < n && simple; ++i) {
    const Point& a = loop[i];
    const Point& b = loop[(i + 1) % n];
    stamps.next(n);
    grid.forEachNear(
        a, b, [](std::uint32_t) { return true; },
        [&](std::uint32_t j) {
          if (++tests > kMaxIntersectionTests) fail(kTooIntricate);
          if (!simple || j <= i || !stamps.firstTime(j)) return;
          const Point& c = loop[j];
          const Point& d = loop[(j + 1) % n];
          const bool follows = j == i + 1, precedes = (j + 1) % n == i;
          if (!follows && !precedes) {
            if (firstContact(a, b, c, d)) simple = false;
            return;
          }
          // Neighbours share one end; they must not fold back onto each other.
          const Point& shared = follows ? b : a;
          const Point& mine = follows ? a : b;
          const Point& theirs = follows ? d : c;
          if (orient(mine, shared, theirs) == 0 && dot(shared, mine, shared, theirs) > 0) simple = false;
        });
  }
  return simple;
}

// Removes loop points that make an edge shorter than minLength, the one whose removal changes the area least first,
// as long as the loop stays simple and keeps three points.
std::vector<Point> removeShortEdges(const std::vector<Point>& loop, double minLength, std::uint64_t& tests) {
  const std::size_t n = loop.size();
  Ring ring(n);
  std::vector<std::size_t>& next = ring.next;
  std::vector<std::size_t>& previous = ring.previous;
  const std::vector<char>& alive = ring.alive;
  // Segment ids: segmentStart[id] = the point it starts at; it is live while that point's next is segmentEnd[id].
  std::vector<std::size_t> segmentStart, segmentEnd;
  SegmentGrid grid(kUnitsPerSpacing);
  const auto addSegment = [&](std::size_t from, std::size_t to) {
    const auto id = static_cast<std::uint32_t>(segmentStart.size());
    segmentStart.push_back(from);
    segmentEnd.push_back(to);
    grid.insert(id, loop[from], loop[to]);
  };
  for (std::size_t i = 0; i < n; ++i) addSegment(i, next[i]);
  Stamps stamps;

  // Would joining a and c directly (dropping the point between) keep the loop simple?
  const auto canJoin = [&](std::size_t a, std::size_t c) {
    const std::size_t before = previous[a], after = next[c];
    if (orient(loop[before], loop[a], loop[c]) == 0 && dot(loop[a], loop[before], loop[a], loop[c]) > 0) return false;
    if (orient(loop[a], loop[c], loop[after]) == 0 && dot(loop[c], loop[a], loop[c], loop[after]) > 0) return false;
    bool clear = true;
    stamps.next(segmentStart.size());
    const auto isLive = [&](std::uint32_t id) {
      const std::size_t s = segmentStart[id], t = segmentEnd[id];
      return alive[s] && alive[t] && next[s] == t;
    };
    grid.forEachNear(loop[a], loop[c], isLive, [&](std::uint32_t id) {
      if (++tests > kMaxIntersectionTests) fail(kTooIntricate);
      if (!clear || !stamps.firstTime(id)) return;
      const std::size_t s = segmentStart[id], t = segmentEnd[id];
      if (s == a || t == c || t == a || s == c) return;  // the two segments being replaced and the neighbours
      if (firstContact(loop[a], loop[c], loop[s], loop[t])) clear = false;
    });
    return clear;
  };
  const auto areaChange = [&](std::size_t i) {
    const Wide a = orient(loop[previous[i]], loop[i], loop[next[i]]);
    return static_cast<double>(a < 0 ? -a : a);
  };
  const auto remove = [&](std::size_t i) {
    const std::size_t a = previous[i], c = next[i];
    ring.unlink(i);
    addSegment(a, c);
  };

  std::vector<std::size_t> work(n);
  for (std::size_t i = 0; i < n; ++i) work[i] = n - 1 - i;
  while (!work.empty() && ring.count > 3) {
    const std::size_t i = work.back();
    work.pop_back();
    if (!alive[i]) continue;
    const std::size_t j = next[i];
    if (length(loop[i], loop[j]) >= minLength) continue;
    std::array<std::size_t, 2> candidates{i, j};
    if (areaChange(j) < areaChange(i)) std::swap(candidates[0], candidates[1]);
    for (const std::size_t candidate : candidates) {
      if (!canJoin(previous[candidate], next[candidate])) continue;
      const std::size_t a = previous[candidate];
      remove(candidate);
      work.push_back(next[a]);
      work.push_back(a);
      work.push_back(previous[a]);
      break;
    }
  }
  return ring.kept(loop);
}

// ----------------------------------------------------------------------------------------------------------------
// The fill.

enum EdgeType : int {
  kBottom = 0,
  kLeft = 1,
  kDiagonal = 2
};  // of a cell: (i,j)-(i+1,j), (i,j)-(i,j+1), (i+1,j)-(i,j+1)

struct Crossing {
  std::int64_t edge = 0;      // lattice edge key
  std::uint32_t segment = 0;  // loop segment loop[segment] - loop[segment + 1]
  Ratio alongEdge;            // where, along the edge's own direction
  Ratio alongSegment;         // where, along the segment
  glm::dvec2 position{0.0};   // integer frame
};

struct Interval {  // inside nodes (begin..end-1, row) are vertices firstVertex...
  Coord begin = 0;
  Coord end = 0;
  std::uint32_t firstVertex = 0;
};

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

double orient(const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& r) {
  return (q.y - p.y) * (r.x - p.x) - (q.x - p.x) * (r.y - p.y);
}

// 1 for an equilateral triangle, 0 for a degenerate one, negative when wound clockwise.
double quality(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  const double squares = glm::dot(b - a, b - a) + glm::dot(c - b, c - b) + glm::dot(a - c, a - c);
  if (!(squares > 0.0)) return 0.0;
  return 2.0 * std::sqrt(3.0) * orient(a, b, c) / squares;
}

class Filler {
 public:
  Filler(const std::vector<Point>& loop, Real spacing) : loop_(loop), spacing_(spacing) {
    Coord maxX = 0, maxZ = 0;
    for (const Point& p : loop_) {
      maxX = std::max(maxX, p.x);
      maxZ = std::max(maxZ, p.z);
    }
    columns_ = floorDiv(maxX, kUnitsPerSpacing) + 2;
    rows_ = floorDiv(maxZ, kUnitsPerSpacing) + 2;
  }

  void run() {
    findCrossings();
    classifyNodes();
    checkParity();
    makeVertices();
    fillWholeTriangles();
    firstPieceTriangle_ = triangles_.size();
    fillClippedTriangles();
    collapseShortEdges();
    flipPoorTriangles();
    claimOutsideNodes();
  }

  Coord columns() const { return columns_; }
  const std::vector<Vertex>& vertices() const { return vertices_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<char>& triangleAlive() const { return triangleAlive_; }

 private:
  // Counts work that is not linear in the size of the mesh (ear clipping, neighbourhoods), so that no outline can
  // make the fill run away.
  void spend(std::size_t steps) {
    work_ += steps;
    if (work_ > kMaxFillWork) {
      fail("outline is too intricate to fill at spacing " + number(spacing_) + " m (far more detail than the spacing)");
    }
  }

  [[noreturn]] void internal(const char* what) const {
    fail("outline could not be meshed at spacing " + number(spacing_) + " m (internal check failed: " + what + ")");
  }

  std::int64_t nodeKey(Coord i, Coord j) const { return j * (columns_ + 1) + i; }
  static Point nodePoint(Coord i, Coord j) { return {i * kUnitsPerSpacing, j * kUnitsPerSpacing}; }
  std::int64_t edgeKey(Coord i, Coord j, EdgeType type) const { return nodeKey(i, j) * 3 + type; }
  std::pair<Point, Point> edgeEnds(std::int64_t key) const {
    const std::int64_t cell = key / 3;
    const Coord i = cell % (columns_ + 1), j = cell / (columns_ + 1);
    switch (static_cast<EdgeType>(key % 3)) {
      case kBottom: return {nodePoint(i, j), nodePoint(i + 1, j)};
      case kLeft: return {nodePoint(i, j), nodePoint(i, j + 1)};
      case kDiagonal: return {nodePoint(i + 1, j), nodePoint(i, j + 1)};
    }
    return {};
  }
  Point loopPoint(std::size_t k) const { return loop_[k % loop_.size()]; }

  // Side of a node against the loop segment p-q, as if every node sat an infinitesimal (e, e^2) up and to the right:
  // a node exactly on the loop is then still on one side, the same side for every question asked about it.
  static int nodeSide(const Point& p, const Point& q, const Point& node) {
    const Wide o = orient(p, q, node);
    if (o != 0) return sign(o);
    if (q.z != p.z) return q.z > p.z ? 1 : -1;
    return q.x > p.x ? -1 : 1;
  }

  void findCrossings() {
    for (std::size_t k = 0; k < loop_.size(); ++k) {
      const Point p = loopPoint(k), q = loopPoint(k + 1);
      forEachCellAlong(p, q, kUnitsPerSpacing, [&](Coord i, Coord j) {
        if (i < 0 || j < 0 || i >= columns_ || j >= rows_) return;
        for (const EdgeType type : {kBottom, kLeft, kDiagonal}) {
          const std::int64_t key = edgeKey(i, j, type);
          const auto [a, b] = edgeEnds(key);
          if (nodeSide(p, q, a) == nodeSide(p, q, b)) continue;
          const Wide op = orient(a, b, p), oq = orient(a, b, q);  // never 0: loop points are off lattice lines
          if (sign(op) == sign(oq)) continue;
          const Wide oa = orient(p, q, a), ob = orient(p, q, b);
          Crossing c;
          c.edge = key;
          c.segment = static_cast<std::uint32_t>(k);
          c.alongEdge = makeRatio(oa, oa - ob);
          c.alongSegment = makeRatio(op, op - oq);
          const double t = toDouble(c.alongSegment);
          c.position = glm::dvec2(static_cast<double>(p.x) + t * static_cast<double>(q.x - p.x),
                                  static_cast<double>(p.z) + t * static_cast<double>(q.z - p.z));
          crossings_.push_back(c);
        }
      });
    }
    std::sort(crossings_.begin(), crossings_.end(), [](const Crossing& a, const Crossing& b) {
      if (a.edge != b.edge) return a.edge < b.edge;
      if (a.segment == b.segment) return false;
      return less(a.alongEdge, b.alongEdge);
    });
    crossings_.erase(
        std::unique(crossings_.begin(), crossings_.end(),
                    [](const Crossing& a, const Crossing& b) { return a.edge == b.edge && a.segment == b.segment; }),
        crossings_.end());
  }

  // Inside nodes, row by row, by the parity of loop crossings to their left (same perturbation as nodeSide).
  void classifyNodes() {
    std::vector<std::pair<Coord, Coord>> rowCrossings;  // (row, first node column at or right of the crossing)
    for (std::size_t k = 0; k < loop_.size(); ++k) {
      const Point p = loopPoint(k), q = loopPoint(k + 1);
      if (p.z == q.z) continue;
      const Coord lo = std::min(p.z, q.z), hi = std::max(p.z, q.z);
      for (Coord j = floorDiv(lo, kUnitsPerSpacing) + 1; j <= floorDiv(hi, kUnitsPerSpacing); ++j) {
        // x of the crossing = numerator / denominator; the first column at or past it is ceil(x / spacing).
        const Wide numerator =
            static_cast<Wide>(p.x) * (q.z - p.z) + static_cast<Wide>(j * kUnitsPerSpacing - p.z) * (q.x - p.x);
        const Ratio x = makeRatio(numerator, q.z - p.z);
        rowCrossings.push_back({j, static_cast<Coord>(ceilDiv(x.numerator, x.denominator * kUnitsPerSpacing))});
      }
    }
    std::sort(rowCrossings.begin(), rowCrossings.end());
    rowFirst_.assign(static_cast<std::size_t>(rows_) + 2, 0);
    std::size_t at = 0;
    std::uint32_t vertex = 0;
    for (Coord j = 0; j <= rows_; ++j) {
      rowFirst_[static_cast<std::size_t>(j)] = intervals_.size();
      std::size_t end = at;
      while (end < rowCrossings.size() && rowCrossings[end].first == j) ++end;
      if ((end - at) % 2 != 0) internal("odd row crossings");
      for (std::size_t c = at; c < end; c += 2) {
        const Coord begin = rowCrossings[c].second, stop = rowCrossings[c + 1].second;
        if (stop <= begin) continue;
        intervals_.push_back({begin, stop, vertex});
        vertex += static_cast<std::uint32_t>(stop - begin);
      }
      at = end;
    }
    rowFirst_[static_cast<std::size_t>(rows_) + 1] = intervals_.size();
    nodeCount_ = vertex;
  }

  std::int64_t nodeVertex(Coord i, Coord j) const {
    if (j < 0 || j > rows_) return kNone;
    const auto begin = intervals_.begin() + static_cast<std::ptrdiff_t>(rowFirst_[static_cast<std::size_t>(j)]);
    const auto end = intervals_.begin() + static_cast<std::ptrdiff_t>(rowFirst_[static_cast<std::size_t>(j) + 1]);
    auto it = std::upper_bound(begin, end, i, [](Coord value, const Interval& s) { return value < s.begin; });
    if (it == begin) return kNone;
    --it;
    if (i >= it->end) return kNone;
    return it->firstVertex + (i - it->begin);
  }
  std::int64_t nodeVertexOfPoint(const Point& p) const {
    return nodeVertex(p.x / kUnitsPerSpacing, p.z / kUnitsPerSpacing);
  }

  // Every lattice edge must be crossed an odd number of times exactly when its ends differ in insideness.
  void checkParity() const {
    for (std::size_t c = 0; c < crossings_.size();) {
      std::size_t end = c;
      while (end < crossings_.size() && crossings_[end].edge == crossings_[c].edge) ++end;
      const auto [a, b] = edgeEnds(crossings_[c].edge);
      const bool differ = (nodeVertexOfPoint(a) >= 0) != (nodeVertexOfPoint(b) >= 0);
      if (differ != ((end - c) % 2 == 1)) internal("crossing parity");
      c = end;
    }
  }

  // Vertices: inside nodes first (row by row), then loop points, then crossings.
  void makeVertices() {
    vertices_.reserve(nodeCount_ + loop_.size() + crossings_.size());
    for (Coord j = 0; j <= rows_; ++j) {
      for (std::size_t s = rowFirst_[static_cast<std::size_t>(j)]; s < rowFirst_[static_cast<std::size_t>(j) + 1];
           ++s) {
        for (Coord i = intervals_[s].begin; i < intervals_[s].end; ++i) {
          Vertex v;
          const Point p = nodePoint(i, j);
          v.position = glm::dvec2(static_cast<double>(p.x), static_cast<double>(p.z));
          v.node = nodeKey(i, j);
          vertices_.push_back(v);
        }
      }
    }
    firstLoopVertex_ = static_cast<std::uint32_t>(vertices_.size());
    for (std::size_t k = 0; k < loop_.size(); ++k) {
      Vertex v;
      v.position = glm::dvec2(static_cast<double>(loop_[k].x), static_cast<double>(loop_[k].z));
      v.corner = static_cast<std::int32_t>(k);
      vertices_.push_back(v);
    }
    firstCrossingVertex_ = static_cast<std::uint32_t>(vertices_.size());
    for (const Crossing& c : crossings_) {
      Vertex v;
      v.position = c.position;
      v.segment = static_cast<std::int32_t>(c.segment);
      vertices_.push_back(v);
    }
    // The lattice triangles the loop crosses, as cell key * 2 + (0 for (p00, p01, p10), 1 for (p10, p01, p11)).
    for (const Crossing& c : crossings_) {
      const std::int64_t cell = c.edge / 3;
      switch (static_cast<EdgeType>(c.edge % 3)) {
        case kBottom:
          clipped_.push_back(cell * 2);
          clipped_.push_back((cell - (columns_ + 1)) * 2 + 1);
          break;
        case kLeft:
          clipped_.push_back(cell * 2);
          clipped_.push_back((cell - 1) * 2 + 1);
          break;
        case kDiagonal:
          clipped_.push_back(cell * 2);
          clipped_.push_back(cell * 2 + 1);
          break;
      }
    }
    std::sort(clipped_.begin(), clipped_.end());
    clipped_.erase(std::unique(clipped_.begin(), clipped_.end()), clipped_.end());
  }

  bool isClipped(std::int64_t triangle) const { return std::binary_search(clipped_.begin(), clipped_.end(), triangle); }

  void addTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    triangles_.push_back({a, b, c});
    triangleAlive_.push_back(1);
  }

  // Lattice triangles wholly inside the loop, wound as the lattice winds them.
  void fillWholeTriangles() {
    for (Coord j = 0; j < rows_; ++j) {
      for (std::size_t s = rowFirst_[static_cast<std::size_t>(j)]; s < rowFirst_[static_cast<std::size_t>(j) + 1];
           ++s) {
        for (Coord i = intervals_[s].begin; i < intervals_[s].end; ++i) {
          const auto v = static_cast<std::uint32_t>(intervals_[s].firstVertex + (i - intervals_[s].begin));
          const std::int64_t up = nodeVertex(i, j + 1), right = nodeVertex(i + 1, j);
          if (!isClipped(nodeKey(i, j) * 2) && up >= 0 && right >= 0) {
            addTriangle(v, static_cast<std::uint32_t>(up), static_cast<std::uint32_t>(right));
          }
          const std::int64_t upLeft = nodeVertex(i - 1, j + 1);
          if (i >= 1 && !isClipped(nodeKey(i - 1, j) * 2 + 1) && upLeft >= 0 && up >= 0) {
            addTriangle(v, static_cast<std::uint32_t>(upLeft), static_cast<std::uint32_t>(up));
          }
        }
      }
    }
  }

  struct Event {
    bool crossing = false;
    std::uint32_t vertex = 0;
    std::size_t index = 0;  // into crossings_
    bool entry = false;     // the loop enters the triangle here
    bool inside = false;    // corner: an inside node
  };

  // Each lattice triangle the loop crosses is replaced by its part inside the loop. That part's boundary alternates
  // between the triangle's edges (from where the loop leaves, onwards) and the loop (from where it enters, to where
  // it leaves next); each closed walk is one piece, triangulated by ear clipping.
  void fillClippedTriangles() {
    std::vector<Event> events;
    std::vector<std::uint32_t> piece;
    for (const std::int64_t triangle : clipped_) {
      const std::int64_t cell = triangle / 2;
      const Coord i = cell % (columns_ + 1), j = cell / (columns_ + 1);
      std::array<std::pair<Coord, Coord>, 3> corners;
      std::array<std::pair<std::int64_t, bool>, 3> edges;  // (edge key, runs along the triangle's direction)
      if (triangle % 2 == 0) {
        corners = {{{i, j}, {i, j + 1}, {i + 1, j}}};
        edges = {{{edgeKey(i, j, kLeft), true}, {edgeKey(i, j, kDiagonal), false}, {edgeKey(i, j, kBottom), false}}};
      } else {
        corners = {{{i + 1, j}, {i, j + 1}, {i + 1, j + 1}}};
        edges = {
            {{edgeKey(i, j, kDiagonal), true}, {edgeKey(i, j + 1, kBottom), true}, {edgeKey(i + 1, j, kLeft), false}}};
      }
      events.clear();
      for (std::size_t e = 0; e < 3; ++e) {
        Event corner;
        const std::int64_t v = nodeVertex(corners[e].first, corners[e].second);
        corner.inside = v >= 0;
        corner.vertex = v >= 0 ? static_cast<std::uint32_t>(v) : 0;
        events.push_back(corner);
        const Point from = nodePoint(corners[e].first, corners[e].second);
        const Point to = nodePoint(corners[(e + 1) % 3].first, corners[(e + 1) % 3].second);
        const auto range = std::equal_range(crossings_.begin(), crossings_.end(), edges[e].first, CrossingEdgeOrder{});
        const auto first = static_cast<std::size_t>(range.first - crossings_.begin());
        const auto last = static_cast<std::size_t>(range.second - crossings_.begin());
        for (std::size_t n = 0; n < last - first; ++n) {
          const std::size_t c = edges[e].second ? first + n : last - 1 - n;
          Event crossing;
          crossing.crossing = true;
          crossing.index = c;
          crossing.vertex = firstCrossingVertex_ + static_cast<std::uint32_t>(c);
          crossing.entry = orient(from, to, loopPoint(crossings_[c].segment)) < 0;
          events.push_back(crossing);
        }
      }
      // Crossings in the order the loop passes them; where two coincide (the loop passes exactly through a corner),
      // the loop enters before it leaves.
      std::vector<std::size_t> alongLoop;
      for (std::size_t e = 0; e < events.size(); ++e) {
        if (events[e].crossing) alongLoop.push_back(e);
      }
      if (alongLoop.empty()) internal("clipped triangle without crossings");
      std::sort(alongLoop.begin(), alongLoop.end(), [&](std::size_t a, std::size_t b) {
        const Crossing& ca = crossings_[events[a].index];
        const Crossing& cb = crossings_[events[b].index];
        if (ca.segment != cb.segment) return ca.segment < cb.segment;
        if (!equal(ca.alongSegment, cb.alongSegment)) return less(ca.alongSegment, cb.alongSegment);
        return events[a].entry && !events[b].entry;
      });
      std::vector<std::size_t> nextAlongLoop(events.size(), 0);
      for (std::size_t n = 0; n < alongLoop.size(); ++n) {
        nextAlongLoop[alongLoop[n]] = alongLoop[(n + 1) % alongLoop.size()];
      }
      std::vector<char> used(events.size(), 0);
      for (std::size_t start = 0; start < events.size(); ++start) {
        if (!events[start].crossing || events[start].entry || used[start]) continue;
        piece.clear();
        std::size_t at = start;
        std::size_t guard = 0;
        do {
          if (++guard > events.size()) internal("piece does not close");
          used[at] = 1;
          piece.push_back(events[at].vertex);
          std::size_t f = (at + 1) % events.size();
          while (!events[f].crossing) {
            if (!events[f].inside) internal("outside corner inside a piece");
            piece.push_back(events[f].vertex);
            f = (f + 1) % events.size();
          }
          if (!events[f].entry) internal("two exits in a row");
          piece.push_back(events[f].vertex);
          const std::size_t exit = nextAlongLoop[f];
          if (events[exit].entry) internal("two entries in a row");
          const Crossing& in = crossings_[events[f].index];
          const Crossing& out = crossings_[events[exit].index];
          const bool sameStretch = in.segment == out.segment && !less(out.alongSegment, in.alongSegment);
          if (!sameStretch) {
            std::size_t k = in.segment;
            std::size_t steps = 0;
            do {
              k = (k + 1) % loop_.size();
              if (++steps > loop_.size()) internal("loop inside one triangle");
              piece.push_back(firstLoopVertex_ + static_cast<std::uint32_t>(k));
            } while (k != out.segment);
          }
          at = exit;
        } while (at != start);
        triangulate(piece);
      }
    }
  }

  struct CrossingEdgeOrder {
    bool operator()(const Crossing& c, std::int64_t key) const { return c.edge < key; }
    bool operator()(std::int64_t key, const Crossing& c) const { return key < c.edge; }
  };

  // Ear clipping, best-shaped ear first. Pieces are small (a triangle's worth of lattice) and simple.
  void triangulate(const std::vector<std::uint32_t>& polygon) {
    std::vector<std::uint32_t> ring = polygon;
    while (ring.size() > 3) {
      const std::size_t n = ring.size();
      spend(n * n);
      std::size_t best = n;
      double bestQuality = -std::numeric_limits<double>::infinity();
      for (std::size_t e = 0; e < n; ++e) {
        const glm::dvec2& p = vertices_[ring[(e + n - 1) % n]].position;
        const glm::dvec2& v = vertices_[ring[e]].position;
        const glm::dvec2& q = vertices_[ring[(e + 1) % n]].position;
        if (!(orient(p, v, q) > 0.0)) continue;
        bool blocked = false;
        for (std::size_t o = 0; o < n && !blocked; ++o) {
          if (o == e || o == (e + 1) % n || o == (e + n - 1) % n) continue;
          const glm::dvec2& w = vertices_[ring[o]].position;
          if (w == p || w == v || w == q) continue;
          blocked = orient(p, v, w) >= 0.0 && orient(v, q, w) >= 0.0 && orient(q, p, w) >= 0.0;
        }
        if (blocked) continue;
        const double shape = quality(p, v, q);
        if (shape > bestQuality) {
          bestQuality = shape;
          best = e;
        }
      }
      if (best == n) {
        // No clean ear: only left by points that coincide (the loop passing exactly through a node). Cut the
        // flattest corner; the zero-area triangle it makes goes with the collapse of its zero-length edge.
        double flattest = -std::numeric_limits<double>::infinity();
        for (std::size_t e = 0; e < n; ++e) {
          const double o = orient(vertices_[ring[(e + n - 1) % n]].position, vertices_[ring[e]].position,
                                  vertices_[ring[(e + 1) % n]].position);
          if (o > flattest) {
            flattest = o;
            best = e;
          }
        }
      }
      addTriangle(ring[(best + n - 1) % n], ring[best], ring[(best + 1) % n]);
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(best));
    }
    if (ring.size() == 3) addTriangle(ring[0], ring[1], ring[2]);
  }

  // --------------------------------------------------------------------------------------------------------------
  // Collapsing short edges.

  bool contains(const Triangle& t, std::uint32_t v) const { return t[0] == v || t[1] == v || t[2] == v; }

  std::vector<std::uint32_t> neighbours(std::uint32_t v) {
    spend(incident_[v].size());
    std::vector<std::uint32_t> result;
    for (const std::uint32_t t : incident_[v]) {
      if (!triangleAlive_[t]) continue;
      for (const std::uint32_t w : triangles_[t]) {
        if (w != v) result.push_back(w);
      }
    }
    std::sort(result.begin(), result.end());
    result.erase(std::unique(result.begin(), result.end()), result.end());
    return result;
  }

  // Link condition: the two ends of an edge may share no neighbour other than the third corners of the triangles on
  // the edge, or collapsing it would fold the mesh onto itself.
  bool canJoin(std::uint32_t gone, std::uint32_t kept) {
    std::vector<std::uint32_t> opposite;
    for (const std::uint32_t t : incident_[gone]) {
      if (!triangleAlive_[t] || !contains(triangles_[t], kept)) continue;
      for (const std::uint32_t w : triangles_[t]) {
        if (w != gone && w != kept) opposite.push_back(w);
      }
    }
    if (opposite.empty()) return false;
    std::sort(opposite.begin(), opposite.end());
    const std::vector<std::uint32_t> a = neighbours(gone), b = neighbours(kept);
    std::vector<std::uint32_t> common;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(common));
    return common == opposite;
  }

  // What a collapse changed, to undo it.
  struct Journal {
    std::vector<std::tuple<std::uint32_t, Triangle, char>> triangles;  // index, corners, alive: before the change
    std::vector<std::pair<std::uint32_t, Vertex>> vertices;
    std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>> incidents;
  };

  // Removes `gone` into `kept`, which keeps its place; `kept` stands for gone's lattice node if it stood for one.
  void collapse(std::uint32_t gone, std::uint32_t kept, Journal& journal) {
    journal.vertices.push_back({gone, vertices_[gone]});
    journal.vertices.push_back({kept, vertices_[kept]});
    journal.incidents.push_back({gone, incident_[gone]});
    journal.incidents.push_back({kept, incident_[kept]});
    for (const std::uint32_t t : incident_[gone]) {
      if (!triangleAlive_[t]) continue;
      journal.triangles.push_back({t, triangles_[t], triangleAlive_[t]});
      if (contains(triangles_[t], kept)) {
        triangleAlive_[t] = 0;
        continue;
      }
      for (std::uint32_t& w : triangles_[t]) {
        if (w == gone) w = kept;
      }
      incident_[kept].push_back(t);
    }
    incident_[gone].clear();
    vertices_[gone].alive = false;
    if (vertices_[gone].node != kNone) vertices_[kept].node = vertices_[gone].node;
  }

  void undo(Journal& journal) {
    for (auto it = journal.triangles.rbegin(); it != journal.triangles.rend(); ++it) {
      triangles_[std::get<0>(*it)] = std::get<1>(*it);
      triangleAlive_[std::get<0>(*it)] = std::get<2>(*it);
    }
    for (auto it = journal.incidents.rbegin(); it != journal.incidents.rend(); ++it) incident_[it->first] = it->second;
    for (auto it = journal.vertices.rbegin(); it != journal.vertices.rend(); ++it) vertices_[it->first] = it->second;
    journal = {};
  }

  double shapeOf(const Triangle& t) const {
    return quality(vertices_[t[0]].position, vertices_[t[1]].position, vertices_[t[2]].position);
  }
  double turnOf(const Triangle& t) const {
    return orient(vertices_[t[0]].position, vertices_[t[1]].position, vertices_[t[2]].position);
  }

  // A triangle a collapse changed must stay counter-clockwise, and be good (quality >= floor) or no worse than half
  // what it was: a poor triangle may get somewhat worse on the way to disappearing, a good one may not turn poor.
  bool acceptable(const Triangle& now, const Triangle& before) const {
    if (!(turnOf(now) > 0.0)) return false;
    const double q = shapeOf(now), was = shapeOf(before);
    return q >= kQualityFloor || (was < kQualityFloor && q >= 0.5 * was);
  }

  // Collapses gone into kept; then, while a triangle it changed is unacceptable and shares a loop edge with kept,
  // sweeps that edge's other end into kept too (a node landing on the loop flattens the slivers between it and the
  // loop, and only removing their loop points removes them). Returns the worst changed triangle's quality, or
  // nothing, with everything undone, if an unacceptable triangle is left.
  std::optional<double> collapseAndSweep(std::uint32_t gone, std::uint32_t kept, Journal& journal) {
    if (!canJoin(gone, kept)) return std::nullopt;
    collapse(gone, kept, journal);
    const auto original = [&](std::uint32_t t) -> const Triangle& {
      for (const auto& entry : journal.triangles) {
        if (std::get<0>(entry) == t) return std::get<1>(entry);
      }
      return triangles_[t];
    };
    const double reach = kSweepDistance * static_cast<double>(kUnitsPerSpacing);
    for (int repair = 0; repair < 8; ++repair) {
      std::optional<std::uint32_t> sweep, flip;
      for (const auto& entry : journal.triangles) {
        const std::uint32_t t = std::get<0>(entry);
        if (!triangleAlive_[t] || acceptable(triangles_[t], original(t))) continue;
        if (!flip) flip = t;
        if (!contains(triangles_[t], kept)) continue;
        for (const std::uint32_t v : triangles_[t]) {
          const Vertex& vertex = vertices_[v];
          if (v == kept || vertex.segment == kNone || vertex.corner != kNone) continue;
          if (vertex.node != kNone && vertices_[kept].node != kNone) continue;
          if (glm::length(vertex.position - vertices_[kept].position) > reach) continue;
          if (trianglesOnEdge(v, kept) == 1 && canJoin(v, kept)) sweep = v;
        }
        if (sweep) break;
      }
      if (sweep) {
        collapse(*sweep, kept, journal);
      } else if (!flip || !flipEdgeOf(*flip, &journal)) {
        break;
      }
    }
    double worst = 1.0;
    for (const auto& entry : journal.triangles) {
      const std::uint32_t t = std::get<0>(entry);
      if (!triangleAlive_[t]) continue;
      if (!acceptable(triangles_[t], original(t))) {
        undo(journal);
        return std::nullopt;
      }
      worst = std::min(worst, shapeOf(triangles_[t]));
    }
    return worst;
  }

  std::size_t trianglesOnEdge(std::uint32_t a, std::uint32_t b) {
    spend(incident_[a].size());
    std::size_t count = 0;
    for (const std::uint32_t t : incident_[a]) {
      if (triangleAlive_[t] && contains(triangles_[t], b)) ++count;
    }
    return count;
  }

  bool tryCollapse(std::uint32_t a, std::uint32_t b) {
    const Vertex& va = vertices_[a];
    const Vertex& vb = vertices_[b];
    if (!va.alive || !vb.alive) return false;
    if (va.node != kNone && vb.node != kNone) return false;            // both stand for lattice nodes: keep both
    std::array<std::pair<std::uint32_t, std::uint32_t>, 2> options{};  // (gone, kept)
    std::size_t count = 0;
    if (va.onLoop() && vb.onLoop()) {
      // Along the loop only (one triangle on the edge), and never removing a loop corner.
      if (trianglesOnEdge(a, b) != 1) return false;
      for (const std::uint32_t gone : {a, b}) {
        if (vertices_[gone].corner == kNone) options[count++] = {gone, gone == a ? b : a};
      }
    } else if (va.onLoop() != vb.onLoop()) {
      const std::uint32_t gone = va.onLoop() ? b : a;  // the node moves onto the loop
      if (!vertices_[gone].movable) return false;
      options[count++] = {gone, gone == a ? b : a};
    }
    // Try each way, keep the one leaving the best worst triangle (the first on a tie). A refused try undoes itself.
    Journal journal;
    if (count == 0) return false;
    const std::optional<double> first = collapseAndSweep(options[0].first, options[0].second, journal);
    if (count == 1) return first.has_value();
    if (first) undo(journal);
    const std::optional<double> second = collapseAndSweep(options[1].first, options[1].second, journal);
    if (second && (!first || *second > *first + 1e-12)) return true;
    if (second) undo(journal);
    if (!first) return false;
    collapseAndSweep(options[0].first, options[0].second, journal);
    return true;
  }

  struct Candidate {
    double length = 0.0;
    std::uint32_t a = 0;
    std::uint32_t b = 0;
    bool operator>(const Candidate& o) const {
      if (length != o.length) return length > o.length;
      if (a != o.a) return a > o.a;
      return b > o.b;
    }
  };

  void collapseShortEdges() {
    // Nodes of clipped triangles may move. They, the loop's vertices and the nodes next to movable ones (which take
    // part in flips) need to know their triangles; the rest of the lattice never changes.
    for (std::size_t t = firstPieceTriangle_; t < triangles_.size(); ++t) {
      for (const std::uint32_t v : triangles_[t]) {
        if (v < firstLoopVertex_) vertices_[v].movable = true;
      }
    }
    for (Vertex& v : vertices_) v.listed = v.movable || v.onLoop();
    for (const Triangle& tri : triangles_) {
      if (vertices_[tri[0]].movable || vertices_[tri[1]].movable || vertices_[tri[2]].movable) {
        for (const std::uint32_t v : tri) vertices_[v].listed = true;
      }
    }
    incident_.assign(vertices_.size(), {});
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      for (const std::uint32_t v : triangles_[t]) {
        if (vertices_[v].listed) incident_[v].push_back(static_cast<std::uint32_t>(t));
      }
    }
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue;
    const auto consider = [&](std::uint32_t a, std::uint32_t b) {
      const Vertex& va = vertices_[a];
      const Vertex& vb = vertices_[b];
      double limit = 0.0;
      if (va.onLoop() && vb.onLoop()) {
        if (va.corner != kNone && vb.corner != kNone) return;  // neither may go
        limit = kMergeDistance;
      } else if ((va.onLoop() && vb.movable) || (vb.onLoop() && va.movable)) {
        limit = kMoveDistance;
      } else {
        return;
      }
      const double d = glm::length(vb.position - va.position);
      if (!(d < limit * static_cast<double>(kUnitsPerSpacing))) return;
      if (va.onLoop() && vb.onLoop() && trianglesOnEdge(a, b) != 1) return;  // a chord: never merged
      queue.push({d, std::min(a, b), std::max(a, b)});
    };
    const auto considerTriangle = [&](std::uint32_t t) {
      const Triangle& tri = triangles_[t];
      consider(tri[0], tri[1]);
      consider(tri[1], tri[2]);
      consider(tri[2], tri[0]);
    };
    for (std::size_t t = firstPieceTriangle_; t < triangles_.size(); ++t)
      considerTriangle(static_cast<std::uint32_t>(t));
    while (!queue.empty()) {
      const Candidate c = queue.top();
      queue.pop();
      if (!vertices_[c.a].alive || !vertices_[c.b].alive || trianglesOnEdge(c.a, c.b) == 0) continue;
      if (!tryCollapse(c.a, c.b)) continue;
      // Edges around the kept vertex changed; edges refused before may now pass, so its triangles are looked at anew.
      const std::uint32_t kept = vertices_[c.a].alive ? c.a : c.b;
      std::erase_if(incident_[kept], [&](std::uint32_t t) { return !triangleAlive_[t]; });
      for (const std::uint32_t t : incident_[kept]) considerTriangle(t);
    }
  }

  // Where the loop turns gently, three of its points can make a flat triangle that no collapse may remove (a loop
  // point is never removed). Flipping the edge between such a triangle and its inner neighbour fixes it. An edge of
  // triangle t is flipped when that clearly raises the worse quality of the two triangles on it; the lattice's own
  // diagonals never qualify (flipping them changes nothing). Returns whether it flipped one.
  bool flipEdgeOf(std::uint32_t t1, Journal* journal) {
    const auto known = [&](std::uint32_t v) { return vertices_[v].listed; };
    for (int e = 0; e < 3; ++e) {
      const Triangle first = triangles_[t1];
      const std::uint32_t a = first[e], b = first[(e + 1) % 3], c = first[(e + 2) % 3];
      if (!known(a) || !known(b) || !known(c)) continue;
      std::optional<std::uint32_t> t2;  // the triangle on the other side of a-b: (b, a, d)
      for (const std::uint32_t t : incident_[a]) {
        if (t != t1 && triangleAlive_[t] && contains(triangles_[t], b)) t2 = t;
      }
      if (!t2) continue;
      const Triangle second = triangles_[*t2];
      std::uint32_t d = second[0];
      for (const std::uint32_t w : second) {
        if (w != a && w != b) d = w;
      }
      if (!known(d)) continue;
      const std::vector<std::uint32_t> around = neighbours(c);
      if (std::binary_search(around.begin(), around.end(), d)) continue;  // c-d exists: flipping would duplicate it
      const Triangle left{a, d, c}, right{b, c, d};
      if (!(turnOf(left) > 0.0) || !(turnOf(right) > 0.0)) continue;  // not convex
      if (std::min(shapeOf(left), shapeOf(right)) < std::min(shapeOf(first), shapeOf(second)) + 0.05) continue;
      if (journal) {
        journal->triangles.push_back({t1, first, 1});
        journal->triangles.push_back({*t2, second, 1});
        for (const std::uint32_t v : {a, b, c, d}) journal->incidents.push_back({v, incident_[v]});
      }
      triangles_[t1] = left;
      triangles_[*t2] = right;
      incident_[c].push_back(*t2);
      incident_[d].push_back(t1);
      std::erase(incident_[a], *t2);
      std::erase(incident_[b], t1);
      return true;
    }
    return false;
  }

  void flipPoorTriangles() {
    std::vector<std::uint32_t> work;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      const Triangle& tri = triangles_[t];
      if (!triangleAlive_[t] || !vertices_[tri[0]].listed || !vertices_[tri[1]].listed || !vertices_[tri[2]].listed) {
        continue;
      }
      if (shapeOf(tri) < kQualityFloor) work.push_back(static_cast<std::uint32_t>(t));
    }
    std::size_t budget = 8 * work.size() + 16;
    while (!work.empty() && budget-- > 0) {
      const std::uint32_t t = work.back();
      work.pop_back();
      if (!triangleAlive_[t] || shapeOf(triangles_[t]) >= kQualityFloor) continue;
      if (flipEdgeOf(t, nullptr)) {
        work.push_back(t);
        // The other triangle changed too; it is rechecked when it is next found poor.
      }
    }
  }

  // A boundary vertex that stands for no lattice node takes the nearest unclaimed outside node within
  // kClaimDistance, nearest pairs first.
  void claimOutsideNodes() {
    std::vector<std::int64_t> claimed;
    std::vector<std::tuple<double, std::uint32_t, std::int64_t>> candidates;
    std::vector<char> used(vertices_.size(), 0);
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      if (!triangleAlive_[t]) continue;
      for (const std::uint32_t v : triangles_[t]) used[v] = 1;
    }
    for (std::uint32_t v = 0; v < vertices_.size(); ++v) {
      const Vertex& vertex = vertices_[v];
      if (!vertex.alive || !used[v]) continue;
      if (vertex.node != kNone) {
        claimed.push_back(vertex.node);
        continue;
      }
      const Coord i0 = static_cast<Coord>(std::floor(vertex.position.x / static_cast<double>(kUnitsPerSpacing)));
      const Coord j0 = static_cast<Coord>(std::floor(vertex.position.y / static_cast<double>(kUnitsPerSpacing)));
      for (Coord j = j0; j <= j0 + 1; ++j) {
        for (Coord i = i0; i <= i0 + 1; ++i) {
          if (i < 0 || j < 0 || i > columns_ || j > rows_ || nodeVertex(i, j) >= 0) continue;
          const Point p = nodePoint(i, j);
          const double d =
              glm::length(vertex.position - glm::dvec2(static_cast<double>(p.x), static_cast<double>(p.z)));
          if (d < kClaimDistance * static_cast<double>(kUnitsPerSpacing)) candidates.push_back({d, v, nodeKey(i, j)});
        }
      }
    }
    std::sort(candidates.begin(), candidates.end());
    std::unordered_set<std::int64_t> taken(claimed.begin(), claimed.end());
    for (const auto& [d, v, node] : candidates) {
      if (vertices_[v].node != kNone || !taken.insert(node).second) continue;
      vertices_[v].node = node;
    }
  }

  const std::vector<Point>& loop_;
  Real spacing_;
  Coord columns_ = 0;  // cells along x; nodes 0..columns_
  Coord rows_ = 0;     // cells along z; nodes 0..rows_
  std::vector<Crossing> crossings_;
  std::vector<std::size_t> rowFirst_;
  std::vector<Interval> intervals_;
  std::uint32_t nodeCount_ = 0;
  std::uint32_t firstLoopVertex_ = 0;
  std::uint32_t firstCrossingVertex_ = 0;
  std::vector<std::int64_t> clipped_;
  std::vector<Vertex> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<char> triangleAlive_;
  std::size_t firstPieceTriangle_ = 0;
  std::vector<std::vector<std::uint32_t>> incident_;
  std::uint64_t work_ = 0;
};

}  // namespace

namespace {

std::string tooSmall(double area, Real spacing) {
  return "outline encloses " + number(area) + " m^2, less than one cell at spacing " + number(spacing) + " m";
}

// Rejects what cannot be an outline before anything is converted.
void checkStroke(const OutlineSpec& spec) {
  // From 1 nm: the loop's grid has 4096 units a spacing, and a metre in units (1 / unit) must stay
  // finite (below about 2.3e-305 m it was infinity, cast to an integer: found by fuzz_outline).
  if (!std::isfinite(spec.spacing) || !(spec.spacing >= kMinSpacing)) {
    fail("outline spacing must be at least 1e-09 m and finite, not " + number(spec.spacing));
  }
  if (!std::isfinite(spec.height)) fail("outline height must be finite");
  const std::vector<glm::dvec2>& points = spec.points;
  for (const glm::dvec2& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) fail("outline has a non-finite point");
  }
  std::array<glm::dvec2, 2> seen{};
  std::size_t distinct = 0;
  for (const glm::dvec2& p : points) {
    if (distinct == 0 || (distinct == 1 && p != seen[0])) {
      seen[distinct++] = p;
    } else if (distinct == 2 && p != seen[0] && p != seen[1]) {
      distinct = 3;
      break;
    }
  }
  if (distinct < 3) fail("outline has fewer than 3 distinct points");
  // Collinear: every point within a relative 1e-12 of the line through the first point and the farthest from it.
  // Coordinates are scaled to [-1, 1] first, so that huge ones cannot overflow.
  double scale = 0.0;
  for (const glm::dvec2& p : points) scale = std::max({scale, std::abs(p.x), std::abs(p.y)});
  const glm::dvec2 a = points[0] / scale;
  double extent = 0.0;
  glm::dvec2 far = a;
  for (const glm::dvec2& p : points) {
    const glm::dvec2 r = p / scale - a;
    const double d = std::max(std::abs(r.x), std::abs(r.y));
    if (d > extent) {
      extent = d;
      far = p / scale;
    }
  }
  const glm::dvec2 direction = glm::normalize(far - a);
  bool collinear = true;
  for (const glm::dvec2& p : points) {
    const glm::dvec2 r = (p / scale - a) / extent;
    if (std::abs(direction.x * r.y - direction.y * r.x) > 1e-12) {
      collinear = false;
      break;
    }
  }
  if (collinear) fail("outline encloses no area (its points are collinear)");
}

struct Loop {
  std::vector<Point> points;  // simple, counter-clockwise seen from +y
  bool tookLargest = false;
};

// Steps 1 to 3 of the header: clean, untangle, orient; then the size checks, before anything big is allocated.
Loop loopFromStroke(const OutlineSpec& spec, const Frame& frame) {
  const double unitsPerMetre = 1.0 / frame.unit;
  std::vector<Point> stroke;
  stroke.reserve(spec.points.size());
  const double minStep = static_cast<double>(kUnitsPerSpacing) / 4.0;
  for (const glm::dvec2& p : spec.points) {
    const Point q{snapToLoopGrid((p.x - frame.origin.x) * unitsPerMetre),
                  snapToLoopGrid((p.y - frame.origin.y) * unitsPerMetre)};
    if (stroke.empty() || length(stroke.back(), q) >= minStep) stroke.push_back(q);
  }
  while (stroke.size() >= 2 && length(stroke.back(), stroke.front()) < minStep) stroke.pop_back();
  stroke = simplify(stroke, minStep);
  const double spacing = spec.spacing;
  // Areas and lengths are measured in cells first: in square metres they may overflow for absurd spacings.
  const double unitsPerCell2 = static_cast<double>(kUnitsPerSpacing * kUnitsPerSpacing);
  if (stroke.size() < 3) {
    fail(tooSmall(std::abs(static_cast<double>(twiceArea(stroke))) * 0.5 / unitsPerCell2 * spacing * spacing, spacing));
  }

  std::uint64_t tests = 0;
  Untangled untangled = untangle(stroke, tests);
  Loop loop;
  loop.tookLargest = untangled.loopsWithArea > 1;
  loop.points = std::move(untangled.loop);
  // A crossing lands on the integer grid, which can (rarely) touch another part of the loop: untangle again.
  for (int attempt = 0;; ++attempt) {
    loop.points = dropStraightPoints(loop.points);
    if (loop.points.size() < 3 || isSimple(loop.points, tests)) break;
    if (attempt == 4) fail(kTooIntricate);
    untangled = untangle(loop.points, tests);
    loop.tookLargest = loop.tookLargest || untangled.loopsWithArea > 1;
    loop.points = std::move(untangled.loop);
  }
  if (loop.points.size() < 3) fail("outline encloses no area (its points are collinear)");
  if (twiceArea(loop.points) < 0) std::reverse(loop.points.begin(), loop.points.end());

  // Area in cells and perimeter in spacings.
  const auto measure = [&](double& cells, double& spacings) {
    cells = static_cast<double>(twiceArea(loop.points)) * 0.5 / unitsPerCell2;
    spacings = 0.0;
    for (std::size_t i = 0; i < loop.points.size(); ++i) {
      spacings += length(loop.points[i], loop.points[(i + 1) % loop.points.size()]);
    }
    spacings /= static_cast<double>(kUnitsPerSpacing);
  };
  double cells = 0.0, spacings = 0.0;
  measure(cells, spacings);
  const double area = cells * spacing * spacing;
  // Inside nodes number about the cells, boundary particles about half a perimeter's worth more (exactly so for a
  // lattice-aligned rectangle: (n + 1)^2 = n^2 + 4n / 2 + 1).
  const double particles = cells + spacings / 2.0 + 1.0;
  if (particles > static_cast<double>(kMaxParticles)) {
    fail("outline of " + number(area) + " m^2 at spacing " + number(spacing) + " m would have about " +
         std::to_string(static_cast<long long>(particles)) + " particles, more than the limit of " +
         std::to_string(kMaxParticles));
  }
  if (cells < 1.0) fail(tooSmall(area, spacing));

  loop.points = dropStraightPoints(removeShortEdges(loop.points, static_cast<double>(kUnitsPerSpacing) / 3.0, tests));
  measure(cells, spacings);
  if (loop.points.size() < 3 || cells < 1.0) fail(tooSmall(cells * spacing * spacing, spacing));
  return loop;
}

}  // namespace

OutlineCloth buildFromOutline(const OutlineSpec& spec, ConstraintSelection selection) {
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
  Frame frame;
  frame.unit = spec.spacing / static_cast<double>(kUnitsPerSpacing);
  frame.origin = low - glm::dvec2(static_cast<double>(kMarginCells) * spec.spacing);

  const Loop loop = loopFromStroke(spec, frame);
  Filler filler(loop.points, spec.spacing);
  filler.run();

  OutlineCloth result;
  result.tookLargestLoop = loop.tookLargest;
  result.loop.reserve(loop.points.size());
  for (const Point& p : loop.points) result.loop.push_back(frame.toWorld(p));

  // Keep the live triangles; a numerically flat one can only be left where points coincide, and covers nothing.
  const std::vector<Vertex>& vertices = filler.vertices();
  const double flat = 1e-9 * static_cast<double>(kUnitsPerSpacing * kUnitsPerSpacing);
  std::vector<Triangle> triangles;
  for (std::size_t t = 0; t < filler.triangles().size(); ++t) {
    if (!filler.triangleAlive()[t]) continue;
    const Triangle& tri = filler.triangles()[t];
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
  ClothRest& rest = result.rest;
  std::vector<std::int64_t> nodeOfParticle;
  std::vector<Vec3> positions;
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    if (particleOf[v] == kNone) continue;
    particleOf[v] = static_cast<std::int64_t>(positions.size());
    const glm::dvec2 p = frame.toWorld(vertices[v].position);
    positions.push_back(Vec3(p.x, spec.height, p.y));
    nodeOfParticle.push_back(vertices[v].node);
  }
  rest.setRestPositions(positions);  // before the rest lengths, which come from the rounded positions
  for (Triangle& tri : triangles) {
    for (std::uint32_t& v : tri) v = static_cast<std::uint32_t>(particleOf[v]);
    rest.triangles.push_back(glm::uvec3(tri[0], tri[1], tri[2]));
  }

  // Constraints by lattice position (see the header).
  const std::int64_t stride = filler.columns() + 1;
  std::vector<std::pair<std::int64_t, ParticleIndex>> byNode;
  for (std::size_t p = 0; p < nodeOfParticle.size(); ++p) {
    if (nodeOfParticle[p] != kNone) byNode.push_back({nodeOfParticle[p], static_cast<ParticleIndex>(p)});
  }
  std::sort(byNode.begin(), byNode.end());
  const auto at = [&](std::int64_t column, std::int64_t row) -> std::optional<ParticleIndex> {
    if (column < 0 || row < 0 || column >= stride) return std::nullopt;
    const std::int64_t key = row * stride + column;
    const auto found = std::lower_bound(byNode.begin(), byNode.end(), std::pair{key, ParticleIndex{0}});
    if (found == byNode.end() || found->first != key) return std::nullopt;
    return found->second;
  };
  using Pair = std::pair<ParticleIndex, ParticleIndex>;
  const auto ordered = [](ParticleIndex a, ParticleIndex b) { return a < b ? Pair{a, b} : Pair{b, a}; };
  std::vector<Pair> edges;
  edges.reserve(rest.triangles.size() * 3);
  std::vector<std::array<ParticleIndex, 3>> sortedTriangles;
  sortedTriangles.reserve(rest.triangles.size());
  for (const glm::uvec3& t : rest.triangles) {
    edges.push_back(ordered(t.x, t.y));
    edges.push_back(ordered(t.y, t.z));
    edges.push_back(ordered(t.z, t.x));
    std::array<ParticleIndex, 3> s{t.x, t.y, t.z};
    std::sort(s.begin(), s.end());
    sortedTriangles.push_back(s);
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::sort(sortedTriangles.begin(), sortedTriangles.end());
  const auto isEdge = [&](ParticleIndex a, ParticleIndex b) {
    return std::binary_search(edges.begin(), edges.end(), ordered(a, b));
  };
  const auto isTriangle = [&](ParticleIndex a, ParticleIndex b, ParticleIndex c) {
    std::array<ParticleIndex, 3> s{a, b, c};
    std::sort(s.begin(), s.end());
    return std::binary_search(sortedTriangles.begin(), sortedTriangles.end(), s);
  };
  const auto add = [&](ConstraintKind kind, ParticleIndex a, ParticleIndex b) {
    const RestReal restLength = toRestLength(glm::length(rest.restPosition(b) - rest.restPosition(a)));
    // Coincident particles cannot survive the collapses; should they, a constraint without a direction is worse
    // than none.
    if (restLength > 0.0) rest.constraints[static_cast<std::size_t>(kind)].push_back({a, b, restLength});
  };
  const auto columnRow = [&](ParticleIndex p) {
    return std::pair{nodeOfParticle[p] % stride, nodeOfParticle[p] / stride};
  };
  for (const auto& [a, b] : edges) {
    bool diagonal = false;
    if (nodeOfParticle[a] != kNone && nodeOfParticle[b] != kNone) {
      const auto [ca, ra] = columnRow(a);
      const auto [cb, rb] = columnRow(b);
      diagonal = std::abs(ca - cb) == 1 && std::abs(ra - rb) == 1;
    }
    if (diagonal ? selection.shear : selection.stretch)
      add(diagonal ? ConstraintKind::shear : ConstraintKind::stretch, a, b);
  }
  for (const auto& [node, p00] : byNode) {
    const std::int64_t column = node % stride, row = node / stride;
    if (selection.shear) {
      const auto p10 = at(column + 1, row), p01 = at(column, row + 1), p11 = at(column + 1, row + 1);
      if (p10 && p01 && p11 && isTriangle(p00, *p01, *p10) && isTriangle(*p10, *p01, *p11)) {
        add(ConstraintKind::shear, p00, *p11);
      }
    }
    if (selection.bend) {
      for (const auto& [dc, dr] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const auto middle = at(column + dc, row + dr), end = at(column + 2 * dc, row + 2 * dr);
        if (middle && end && isEdge(p00, *middle) && isEdge(*middle, *end) && !isEdge(p00, *end)) {
          add(ConstraintKind::bend, p00, *end);
        }
      }
    }
  }
  return result;
}

}  // namespace drape::sim
