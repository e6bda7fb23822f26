#include "fill.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

namespace drape::mesh::detail {
namespace {

// Steps the fill may take beyond its linear work before the outline is called too intricate (about
// half a second). Only strokes with far more detail than the spacing get there.
constexpr std::uint64_t kMaxFillWork = 200'000'000;
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

// 1 for an equilateral triangle, 0 for a degenerate one, negative when wound clockwise.
double quality(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  const double squares = glm::dot(b - a, b - a) + glm::dot(c - b, c - b) + glm::dot(a - c, a - c);
  if (!(squares > 0.0)) return 0.0;
  return 2.0 * std::sqrt(3.0) * orient(a, b, c) / squares;
}

class Filler {
 public:
  Filler(const std::vector<Point>& loop, double spacing) : loop_(loop), spacing_(spacing) {
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

  Fill take() { return {std::move(vertices_), std::move(triangles_), std::move(triangleAlive_), columns_}; }

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
  double spacing_;
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

Fill fillLoop(const std::vector<Point>& loop, double spacing) {
  Filler filler(loop, spacing);
  filler.run();
  return filler.take();
}

}  // namespace drape::mesh::detail
