#include "loop.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

namespace drape::mesh::detail {
namespace {

constexpr double kMinSpacing = 1e-9;  // m
// Segment pairs the untangling may test before the outline is called too intricate (about half a
// second). Only strokes with far more detail than the spacing get there.
constexpr std::uint64_t kMaxIntersectionTests = 50'000'000;
constexpr const char* kTooIntricate = "outline is too intricate to untangle (far more detail than the spacing)";

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

}  // namespace

std::string tooSmall(double area, double spacing) {
  return "outline encloses " + number(area) + " m^2, less than one cell at spacing " + number(spacing) + " m";
}

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

}  // namespace drape::mesh::detail
