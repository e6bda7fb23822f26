#include "collision/self_contact.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "collision/contacts.hpp"
#include "collision/exact_triangles.hpp"

namespace drape::sim::contact {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
// Sweeps of the contacts a substep: each pair is pushed out in the first; the rest settle pairs
// that push each other (a particle between two layers).
constexpr int kSweeps = 4;
// Room left for rounding where the fail-safe proves two primitives apart, m: far above the error of
// the distances (1e-12 m), above the exact test's grid (6e-8 m).
constexpr Real kProofMargin = 1e-6;
// A fold between neighbours whose signed volume at x0 is under this times the product of the lengths
// of its three edges from a shared corner (about the sine of its angle) lies flat: which side its
// free corner was on is rounding, and no side it goes to passes it through. A crumple closes
// creases flat: without this, the spread gesture zoned 2,759 such folds and ended 5.5 cm high.
constexpr Real kFlatFold = 1e-3;

// The times in [0, 1] where c0 + c1 t + c2 t^2 + c3 t^3 changes sign (at most three), found by
// bisection between its turning points: the signed volume of four points moving straight, which is
// what a fold's closing is (a linear guess from its two ends put the crossing of a fold thrown
// through itself at 50 m/s on the wrong side of its crease, and the fail-safe let it through).
int signChangesIn01(const std::array<Real, 4>& c, std::array<Real, 3>& roots) {
  const auto f = [&](Real t) { return c[0] + t * (c[1] + t * (c[2] + t * c[3])); };
  std::array<Real, 4> ends{0.0};  // 0, the turning points inside (0, 1), 1
  int count = 1;
  const Real a = 3.0 * c[3], b = 2.0 * c[2], d = c[1];
  const Real scale = std::max({std::abs(a), std::abs(b), std::abs(d)});
  if (scale > 0.0) {
    std::array<Real, 2> turning{};
    int turnings = 0;
    if (std::abs(a) > 1e-12 * scale) {
      const Real discriminant = b * b - 4.0 * a * d;
      if (discriminant >= 0.0) {
        const Real root = std::sqrt(discriminant);
        const Real q = -0.5 * (b + (b >= 0.0 ? root : -root));
        if (q != 0.0) turning[turnings++] = d / q;
        turning[turnings++] = q / a;
      }
    } else if (b != 0.0) {
      turning[turnings++] = -d / b;
    }
    std::sort(turning.begin(), turning.begin() + turnings);
    for (int k = 0; k < turnings; ++k) {
      if (turning[k] > 0.0 && turning[k] < 1.0) ends[count++] = turning[k];
    }
  }
  ends[count++] = 1.0;
  int found = 0;
  for (int k = 0; k + 1 < count; ++k) {
    Real lo = ends[k], hi = ends[k + 1];
    Real flo = f(lo), fhi = f(hi);
    if (!(flo * fhi < 0.0)) continue;
    for (int i = 0; i < 64 && hi - lo > 1e-15; ++i) {
      const Real mid = 0.5 * (lo + hi), fmid = f(mid);
      if ((fmid < 0.0) == (flo < 0.0)) {
        lo = mid;
        flo = fmid;
      } else {
        hi = mid;
      }
    }
    roots[static_cast<std::size_t>(found++)] = 0.5 * (lo + hi);
  }
  return found;
}
// Two points closer than this at x0 give no direction to keep apart along (a closed seam aside:
// SelfContact::measure).
constexpr Real kCoincident = 1e-12;
// How far the contacts' sweep parts a closed seam's two sides where they meet (m): 168 points of
// the exact test's grid, far under what the eye or the contact distance sees.
constexpr Real kSeamApart = 1e-5;
// A pair's separation where nothing is proven.
constexpr float kUnproven = -std::numeric_limits<float>::infinity();
// How many times its rest size a triangle or edge may be stretched and still take part (longer
// than its cloth at rest too, it takes none: findPairs).
constexpr Real kTorn = 10.0;

// Where more than one particle in this many leaves its box (as a substep begins, or in the
// fail-safe), the pairs are found again by a search; fewer, by pairing again what their primitives'
// boxes overlap (a refresh).
constexpr std::size_t kStraysForSearch = 8;
// Triangles a leaf of the broad phase's tree holds at most.
constexpr std::size_t kLeafTriangles = 2;
// Pairs of nodes the walk of the broad phase's tree is cut into, at least, for the threads to share.
constexpr std::size_t kWalkTasks = 64;
// Pairs of leaves a thread takes at a time when it lists their primitives' pairs.
constexpr std::size_t kLeafPairBlock = 256;
// A refresh's primitives a block (the strays' vertices, triangles and edges, each walked down the
// tree): a few hundred pairs each.
constexpr std::size_t kRefreshBlock = 64;
// How far a cluster of a refresh's primitives, walked down the tree as one, may spread: the sum of
// its box's sides, at most this times its largest member's.
constexpr float kClusterSpread = 2.0f;

// Closest point of triangle abc to p, as barycentric weights of a, b, c (by the triangle's Voronoi
// regions: a corner, an edge, or the inside).
Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {1.0, 0.0, 0.0};
  const Vec3 bp = p - b;
  const Real d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return {0.0, 1.0, 0.0};
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) {
    const Real t = d1 / (d1 - d3);
    return {1.0 - t, t, 0.0};
  }
  const Vec3 cp = p - c;
  const Real d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 0.0, 1.0};
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) {
    const Real t = d2 / (d2 - d6);
    return {1.0 - t, 0.0, t};
  }
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
    const Real t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0.0, 1.0 - t, t};
  }
  const Real sum = va + vb + vc;
  if (!(sum > 0.0)) {
    // No area: the nearest corner will do.
    const Real da = glm::dot(ap, ap), db = glm::dot(bp, bp), dc = glm::dot(cp, cp);
    return da <= db && da <= dc ? Vec3{1.0, 0.0, 0.0} : db <= dc ? Vec3{0.0, 1.0, 0.0} : Vec3{0.0, 0.0, 1.0};
  }
  const Real v = vb / sum, w = vc / sum;
  return {1.0 - v - w, v, w};
}

// Closest points of segments p1q1 and p2q2: p1 + s (q1 - p1) and p2 + t (q2 - p2).
std::pair<Real, Real> closestOnSegments(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const Real a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
  constexpr Real tiny = 1e-30;
  if (a <= tiny && e <= tiny) return {0.0, 0.0};
  if (a <= tiny) return {0.0, std::clamp(f / e, 0.0, 1.0)};
  const Real c = glm::dot(d1, r);
  if (e <= tiny) return {std::clamp(-c / a, 0.0, 1.0), 0.0};
  const Real b = glm::dot(d1, d2);
  const Real denominator = a * e - b * b;
  Real s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
  Real t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return {s, t};
}

struct Weights {
  Real c[4];
};

Weights vertexTriangleWeights(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 bary = closestOnTriangle(p, a, b, c);
  return {{1.0, -bary.x, -bary.y, -bary.z}};
}

Weights edgeEdgeWeights(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1) {
  const auto [s, t] = closestOnSegments(a0, a1, b0, b1);
  return {{1.0 - s, s, -(1.0 - t), -t}};
}

// sum_k c_k x_k: the first point minus the second.
Vec3 between(const Weights& w, const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3) {
  return p0 * w.c[0] + p1 * w.c[1] + p2 * w.c[2] + p3 * w.c[3];
}

// A box in single precision, grown to hold the double one.
// (Clamped to the float range first: a torn primitive's empty box is +-DBL_MAX, which no float
// holds, and converting it would be undefined. A NaN stays NaN.)
float toFloat(Real v) {
  constexpr Real most = std::numeric_limits<float>::max();
  return static_cast<float>(v < -most ? -most : v > most ? most : v);
}
glm::vec3 below(const Vec3& x) {
  return {std::nextafter(toFloat(x.x), -INFINITY), std::nextafter(toFloat(x.y), -INFINITY),
          std::nextafter(toFloat(x.z), -INFINITY)};
}
glm::vec3 above(const Vec3& x) {
  return {std::nextafter(toFloat(x.x), INFINITY), std::nextafter(toFloat(x.y), INFINITY),
          std::nextafter(toFloat(x.z), INFINITY)};
}

// A point's largest coordinate, in magnitude (infinite where one is NaN: no room is then enough).
Real largest(const Vec3& x) {
  const Real m = std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)});
  return std::isnan(x.x + x.y + x.z) ? std::numeric_limits<Real>::infinity() : m;
}

// The float at or below v (a proof's separation kept in single precision must not grow).
float floatBelow(Real v) {
  constexpr Real most = std::numeric_limits<float>::max();
  if (std::isnan(v) || v < -most) return kUnproven;
  if (v > most) return std::numeric_limits<float>::max();  // (converting it would be undefined)
  const auto f = static_cast<float>(v);
  return static_cast<Real>(f) > v ? std::nextafter(f, -INFINITY) : f;
}

bool overlap(const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& otherLo, const glm::vec3& otherHi) {
  return lo.x <= otherHi.x && otherLo.x <= hi.x && lo.y <= otherHi.y && otherLo.y <= hi.y && lo.z <= otherHi.z &&
         otherLo.z <= hi.z;
}

}  // namespace

static_assert(sizeof(SelfContact::Pair) <= 20, "a listed pair is 20 bytes: there can be a hundred a particle");

std::size_t SelfContact::bytes() const {
  const auto b = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  std::size_t total = b(clothOf_) + b(rest_) + b(clothSize_) + b(triangles_) + b(edges_) + b(edgeTriangles_) +
                      b(vertexStart_) + b(vertexTriangles_) + b(x0_) + b(x_) + b(w_) + b(planes_) + b(lower_) +
                      b(upper_) + b(boxLower_) + b(boxUpper_) + b(pairs_) + b(contacts_) + b(active_) + b(x0Measured_) +
                      b(xMeasured_) + b(reach_) + b(primitiveReach_) + b(runNear_) + b(triangleMoved_) + b(zone_) +
                      b(inZone_) + b(heavy_) + b(stays_) + b(staysRoot_) + b(stuck_) + b(everPassing_) + b(tests_) +
                      b(hits_) + b(slot0_) + b(slotX_) + b(which0_) + b(whichX_) + b(made0_) + b(madeX_) +
                      b(affected_) + b(movedTriangles_) + b(primitiveMoved_) + b(strays_) + b(walk_) + b(refreshed_);
  total += b(nodes_) + b(leafTriangleStart_) + b(leafTriangles_) + b(leafVertexStart_) + b(leafVertices_) +
           b(leafEdgeStart_) + b(leafEdges_) + b(leafNode_) + b(primitiveLeaf_) + b(leafPairs_) + b(walkTests_) +
           b(boxTests_);
  for (const std::vector<std::uint64_t>& walked : walked_) total += b(walked);
  for (const std::vector<Pair>& found : found_) total += b(found);
  for (const std::vector<std::uint64_t>& found : scanTests_) total += b(found);
  for (const auto& measured : scanContacts_) total += b(measured);
  total += b(scanTested_);
  return total;
}

void SelfContact::buildMesh(const std::vector<ClothRecord>& cloths) {
  clothOf_.clear();
  rest_.clear();
  clothSize_.clear();
  triangles_.clear();
  clothStart_.clear();
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    const auto base = static_cast<std::uint32_t>(clothOf_.size());
    clothStart_.push_back(base);
    const Cloth& cloth = cloths[c].cloth;
    // The cloth's size at rest: the diagonal of its rest shape's box, squared (0 with no particle).
    Vec3 lo(std::numeric_limits<Real>::max()), hi(std::numeric_limits<Real>::lowest());
    for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
      clothOf_.push_back(static_cast<std::uint32_t>(c));
      rest_.push_back(cloth.rest.restPosition(i));
      lo = glm::min(lo, rest_.back());
      hi = glm::max(hi, rest_.back());
    }
    clothSize_.push_back(lo.x <= hi.x ? glm::dot(hi - lo, hi - lo) : 0.0);
    for (const glm::uvec3& t : cloth.rest.triangles) triangles_.push_back(t + base);
  }
  const std::size_t n = clothOf_.size();
  // Edges: each once, with the (one or two) triangles on it.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sides;
  sides.reserve(triangles_.size() * 3);
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles_[t][k], b = triangles_[t][(k + 1) % 3];
      sides.push_back({(static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b), t});
    }
  }
  std::sort(sides.begin(), sides.end());
  edges_.clear();
  edgeTriangles_.clear();
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && sides[j].first == sides[i].first) ++j;
    edges_.push_back({static_cast<std::uint32_t>(sides[i].first >> 32), static_cast<std::uint32_t>(sides[i].first)});
    edgeTriangles_.push_back(sides[i].second);
    edgeTriangles_.push_back(j - i > 1 ? sides[i + 1].second : kNone);
    i = j;
  }
  vertexStart_.assign(n + 1, 0);
  for (const glm::uvec3& t : triangles_) {
    for (int k = 0; k < 3; ++k) ++vertexStart_[t[k] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) vertexStart_[i + 1] += vertexStart_[i];
  vertexTriangles_.resize(vertexStart_[n]);
  std::vector<std::uint32_t> fill(vertexStart_.begin(), vertexStart_.end() - 1);
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    for (int k = 0; k < 3; ++k) vertexTriangles_[fill[triangles_[t][k]]++] = t;
  }
  meshParticles_ = n;
  buildTree();
}

void SelfContact::buildTree() {
  const std::size_t n = clothOf_.size(), nt = triangles_.size();
  // The items the tree splits: the triangles (ids 0 .. nt - 1), then the particles in no triangle
  // (nt + the particle), each at its rest centroid; cloth by cloth.
  std::vector<std::uint32_t> items;
  std::vector<Vec3> centre(nt + n);
  std::vector<std::uint32_t> cloth(nt + n);
  for (std::uint32_t t = 0; t < nt; ++t) {
    const glm::uvec3 v = triangles_[t];
    items.push_back(t);
    centre[t] = (rest_[v[0]] + rest_[v[1]] + rest_[v[2]]) / 3.0;
    cloth[t] = clothOf_[v[0]];
  }
  for (std::uint32_t v = 0; v < n; ++v) {
    if (vertexStart_[v] != vertexStart_[v + 1]) continue;
    const auto id = static_cast<std::uint32_t>(nt + v);
    items.push_back(id);
    centre[id] = rest_[v];
    cloth[id] = clothOf_[v];
  }
  std::stable_sort(items.begin(), items.end(), [&](std::uint32_t a, std::uint32_t b) { return cloth[a] < cloth[b]; });

  nodes_.clear();
  leafNode_.clear();
  leafTriangles_.clear();
  leafTriangleStart_.assign(1, 0);
  std::vector<std::uint32_t> leafOfItem(nt + n, kNone);
  const auto build = [&](auto&& self, std::size_t begin, std::size_t end) -> std::uint32_t {
    const auto node = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    if (end - begin <= kLeafTriangles) {
      const auto leaf = static_cast<std::uint32_t>(leafNode_.size());
      leafNode_.push_back(node);
      nodes_[node].left = leaf;
      nodes_[node].right = kNone;
      for (std::size_t i = begin; i < end; ++i) {
        leafOfItem[items[i]] = leaf;
        if (items[i] < nt) leafTriangles_.push_back(items[i]);
      }
      leafTriangleStart_.push_back(static_cast<std::uint32_t>(leafTriangles_.size()));
      return node;
    }
    std::size_t middle = begin + (end - begin) / 2;
    if (cloth[items[begin]] != cloth[items[end - 1]]) {
      // Cloths apart: at the border between two cloths nearest the middle.
      const std::uint32_t c = cloth[items[middle]];
      const auto byCloth = [&](std::uint32_t item, std::uint32_t value) { return cloth[item] < value; };
      const auto from = static_cast<std::size_t>(
          std::lower_bound(items.begin() + begin, items.begin() + end, c, byCloth) - items.begin());
      const auto to = static_cast<std::size_t>(
          std::lower_bound(items.begin() + begin, items.begin() + end, c + 1, byCloth) - items.begin());
      middle = from > begin && (to >= end || middle - from <= to - middle) ? from : to;
    } else {
      // Halved at the median along the longest side of the centroids' box.
      Vec3 lo(std::numeric_limits<Real>::max()), hi(std::numeric_limits<Real>::lowest());
      for (std::size_t i = begin; i < end; ++i) {
        lo = glm::min(lo, centre[items[i]]);
        hi = glm::max(hi, centre[items[i]]);
      }
      const Vec3 size = hi - lo;
      const int axis = size.x >= size.y && size.x >= size.z ? 0 : size.y >= size.z ? 1 : 2;
      std::nth_element(items.begin() + begin, items.begin() + middle, items.begin() + end,
                       [&](std::uint32_t a, std::uint32_t b) {
                         return centre[a][axis] < centre[b][axis] || (centre[a][axis] == centre[b][axis] && a < b);
                       });
    }
    const std::uint32_t left = self(self, begin, middle);
    const std::uint32_t right = self(self, middle, end);
    nodes_[node].left = left;
    nodes_[node].right = right;
    return node;
  };
  if (!items.empty()) build(build, 0, items.size());

  // Vertices and edges go to the leaf of their first triangle.
  const std::size_t leaves = leafNode_.size();
  const auto group = [&](std::vector<std::uint32_t>& start, std::vector<std::uint32_t>& members, std::size_t count,
                         auto&& leafOf) {
    start.assign(leaves + 1, 0);
    for (std::size_t i = 0; i < count; ++i) ++start[leafOf(i) + 1];
    for (std::size_t l = 0; l < leaves; ++l) start[l + 1] += start[l];
    members.resize(count);
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < count; ++i) members[fill[leafOf(i)]++] = static_cast<std::uint32_t>(i);
  };
  const auto vertexLeaf = [&](std::size_t v) {
    return vertexStart_[v] != vertexStart_[v + 1] ? leafOfItem[vertexTriangles_[vertexStart_[v]]] : leafOfItem[nt + v];
  };
  const auto edgeLeaf = [&](std::size_t e) { return leafOfItem[edgeTriangles_[2 * e]]; };
  group(leafVertexStart_, leafVertices_, n, vertexLeaf);
  group(leafEdgeStart_, leafEdges_, edges_.size(), edgeLeaf);
  primitiveLeaf_.resize(n + nt + edges_.size());
  for (std::size_t v = 0; v < n; ++v) primitiveLeaf_[v] = vertexLeaf(v);
  for (std::size_t t = 0; t < nt; ++t) primitiveLeaf_[n + t] = leafOfItem[t];
  for (std::size_t e = 0; e < edges_.size(); ++e) primitiveLeaf_[n + nt + e] = edgeLeaf(e);
}

void SelfContact::fitTree() {
  const std::size_t n = x_.size(), nt = triangles_.size();
  const glm::vec3 none(std::numeric_limits<float>::max());
  for (std::size_t l = 0; l < leafNode_.size(); ++l) {
    glm::vec3 lo = none, hi = -none;
    const auto add = [&](std::size_t box) {
      lo = glm::min(lo, boxLower_[box]);
      hi = glm::max(hi, boxUpper_[box]);
    };
    for (std::uint32_t k = leafVertexStart_[l]; k < leafVertexStart_[l + 1]; ++k) add(leafVertices_[k]);
    for (std::uint32_t k = leafTriangleStart_[l]; k < leafTriangleStart_[l + 1]; ++k) add(n + leafTriangles_[k]);
    for (std::uint32_t k = leafEdgeStart_[l]; k < leafEdgeStart_[l + 1]; ++k) add(n + nt + leafEdges_[k]);
    nodes_[leafNode_[l]].lower = lo;
    nodes_[leafNode_[l]].upper = hi;
  }
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    Node& node = nodes_[i];
    if (node.right == kNone) continue;
    node.lower = glm::min(nodes_[node.left].lower, nodes_[node.right].lower);
    node.upper = glm::max(nodes_[node.left].upper, nodes_[node.right].upper);
  }
}

void SelfContact::gather(const std::vector<ClothRecord>& cloths, const std::vector<std::vector<Vec3>>* before) {
  const std::size_t n = clothOf_.size();
  x0_.resize(n);
  x_.resize(n);
  w_.resize(n);
  planes_.clear();
  std::size_t k = 0;
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    const ParticleState& s = cloths[c].cloth.state;
    const SolverScratch& contacts = cloths[c].work->solver;
    const bool planes = !before && contacts.contactCollider.size() == s.position.size();
    for (std::size_t i = 0; i < s.position.size(); ++i, ++k) {
      // Where the substep began (the integration left it there), or where the move began.
      x0_[k] = before ? (*before)[c][i] : s.previousPosition[i];
      x_[k] = s.position[i];
      w_[k] = s.inverseMass[i];
      if (planes && contacts.contactCollider[i] >= 0) {
        planes_.push_back({static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(i),
                           contacts.contactNormal[i], contacts.contactOffset[i]});
      }
    }
  }
}

// A triangle or edge stretched past kTorn times its rest size and longer than its whole cloth at
// rest is no cloth any more (a finger flung its patch 100 m): it takes no part, or its box would
// pair it with everything in between. (Not by its rest size alone: on a fine lattice, where a twist
// winds the cloth round a grip, self-contact holds some of the grip's particles back while the
// rest move on, the links between them stretch ten times over within a few centimetres, and
// those triangles passed through the layers.)
bool SelfContact::torn(const std::uint32_t* v, int count) const {
  const auto longest = [&](const std::vector<Vec3>& x) {
    Real most = 0.0;
    for (int i = 0; i < count; ++i) {
      const Vec3 d = x[v[i]] - x[v[(i + 1) % count]];
      most = std::max(most, glm::dot(d, d));
    }
    return most;
  };
  return longest(x_) > std::max(kTorn * kTorn * longest(rest_), clothSize_[clothOf_[v[0]]]) + 4.0 * grow_ * grow_;
}

void SelfContact::boxPrimitive(std::size_t k) {
  const std::size_t n = x_.size(), nt = triangles_.size();
  const bool triangle = k < n + nt;
  const std::uint32_t* v = triangle ? &triangles_[k - n][0] : &edges_[k - n - nt][0];
  const int count = triangle ? 3 : 2;
  if (torn(v, count)) {
    lower_[k] = Vec3(std::numeric_limits<Real>::max());
    upper_[k] = Vec3(std::numeric_limits<Real>::lowest());
  } else {
    lower_[k] = lower_[v[0]];
    upper_[k] = upper_[v[0]];
    for (int i = 1; i < count; ++i) {
      lower_[k] = glm::min(lower_[k], lower_[v[i]]);
      upper_[k] = glm::max(upper_[k], upper_[v[i]]);
    }
  }
  // As the tree keeps it: single precision, rounded outwards.
  boxLower_[k] = below(lower_[k]);
  boxUpper_[k] = above(upper_[k]);
}

// Whether the two primitives' boxes lie apart along the line between their centres: the hull of
// the first `split` corners' boxes and that of the rest. Boxes that overlap may still: a vertex's
// box inside a tilted triangle's box, a layer above it. Then, as for boxes that do not overlap,
// while every particle keeps half a `distance` inside its box the two stay at least `distance`
// apart (each hull shrinks by half a distance along the line); so the pair is not listed. In single
// precision, from the boxes as the tree keeps them (rounded outwards, so holding the double ones),
// and all along the line as it is (between twice the boxes' centres, not of unit length), with
// room for rounding that grows with the coordinates: only where they are apart beyond it.
bool SelfContact::apartBoxes(const std::uint32_t* corners, int split) const {
  glm::vec3 twice[4], size[4];  // each corner's box: twice its centre, and its sides
  for (int k = 0; k < 4; ++k) {
    twice[k] = boxLower_[corners[k]] + boxUpper_[corners[k]];
    size[k] = boxUpper_[corners[k]] - boxLower_[corners[k]];
  }
  const glm::vec3 axis = split == 1 ? twice[0] - (twice[1] + twice[2] + twice[3]) * (1.0f / 3.0f)
                                    : (twice[0] + twice[1]) * 0.5f - (twice[2] + twice[3]) * 0.5f;
  const glm::vec3 along = glm::abs(axis);
  float lo[2] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
  float hi[2] = {std::numeric_limits<float>::lowest(), std::numeric_limits<float>::lowest()};
  float scale = 0.0f;
  for (int k = 0; k < 4; ++k) {
    const float at = glm::dot(twice[k], axis), half = glm::dot(size[k], along);
    const int side = k < split ? 0 : 1;
    lo[side] = std::min(lo[side], at - half);
    hi[side] = std::max(hi[side], at + half);
    scale = std::max(scale, glm::dot(glm::abs(twice[k]), along) + half);
  }
  // A few single-precision roundings of figures up to `scale` lie far under 1e-5 of it; and 1 nm.
  const float margin = 1e-5f * scale + 2e-9f * (along.x + along.y + along.z);
  // Not apart unless every figure is finite (min and max pass a NaN by).
  if (!std::isfinite(lo[0] + hi[0] + lo[1] + hi[1] + margin) || !(margin > 0.0f)) return false;
  return hi[0] + margin < lo[1] || hi[1] + margin < lo[0];
}

void SelfContact::listVertexTriangle(std::uint32_t v, std::uint32_t t, std::vector<Pair>& out) const {
  const glm::uvec3 c = triangles_[t];
  if (c[0] == v || c[1] == v || c[2] == v) return;
  const std::uint32_t corners[4] = {v, c[0], c[1], c[2]};
  if (apartBoxes(corners, 1)) return;
  out.push_back({v, t, kFar, kUnproven, false, kRestUnknown});
}

void SelfContact::listEdgeEdge(std::uint32_t e, std::uint32_t f, std::vector<Pair>& out) const {
  const glm::uvec2 a = edges_[std::min(e, f)], b = edges_[std::max(e, f)];
  if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) return;
  const std::uint32_t corners[4] = {a[0], a[1], b[0], b[1]};
  if (apartBoxes(corners, 2)) return;
  out.push_back({std::min(e, f), std::max(e, f), kFar, kUnproven, true, kRestUnknown});
}

void SelfContact::findPairs(Real distance, Real ahead, Workers& workers) {
  const std::size_t n = x_.size(), nt = triangles_.size(), ne = edges_.size();
  // Boxes: each particle's motion, from x0 on for `ahead` times its motion in this substep (the
  // substeps left in the step, or more for a cloth carried along: findPairsIfNeeded; the pairs then
  // serve for all of them while the particles keep within), grown by `distance`, so that two boxes
  // overlap wherever two primitives may come within twice that. The solve may push a particle up to
  // `distance` beyond, before the pairs must be found again (SelfContact::strays).
  ahead_ = ahead;
  served_ = 1;
  const Real grow = distance;
  lower_.resize(n + nt + ne);
  upper_.resize(n + nt + ne);
  grow_ = grow;
  boxLower_.resize(n + nt + ne);
  boxUpper_.resize(n + nt + ne);
  // Each box on its own: the particles', then the triangles' and edges' from theirs.
  workers.run(
      n,
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t i = begin; i < end; ++i) {
          const Vec3 to = x0_[i] + (x_[i] - x0_[i]) * ahead;
          lower_[i] = glm::min(glm::min(x0_[i], x_[i]), to) - grow;
          upper_[i] = glm::max(glm::max(x0_[i], x_[i]), to) + grow;
          boxLower_[i] = below(lower_[i]);
          boxUpper_[i] = above(upper_[i]);
        }
      },
      1024);
  workers.run(
      nt + ne,
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t k = begin; k < end; ++k) boxPrimitive(n + k);
      },
      1024);
  fitTree();
  ++stats_.searches;

  // The pairs of leaves whose boxes overlap, each once (a leaf with itself too), in the walk's order.
  const auto both = [](std::uint32_t a, std::uint32_t b) { return (static_cast<std::uint64_t>(a) << 32) | b; };
  const auto isLeaf = [&](const Node& node) { return node.right == kNone; };
  const auto extent = [](const Node& node) {
    const glm::vec3 size = node.upper - node.lower;
    return size.x + size.y + size.z;
  };
  // One step of the walk from a pair of nodes: the pair of leaves it is, or the pairs of nodes to
  // look at next (in the order the walk takes them), or nothing where their boxes lie apart.
  const auto step = [&](std::uint64_t pair, auto&& leaves, auto&& next, std::int64_t& tests) {
    const auto a = static_cast<std::uint32_t>(pair >> 32), b = static_cast<std::uint32_t>(pair);
    const Node& p = nodes_[a];
    const Node& q = nodes_[b];
    if (a == b) {
      if (isLeaf(p)) {
        leaves(both(p.left, p.left));
      } else {
        // The left half, the right half, then the two against each other.
        next(both(p.left, p.left));
        next(both(p.right, p.right));
        next(both(p.left, p.right));
      }
      return;
    }
    ++tests;
    if (!overlap(p.lower, p.upper, q.lower, q.upper)) return;
    if (isLeaf(p) && isLeaf(q)) {
      leaves(both(std::min(p.left, q.left), std::max(p.left, q.left)));
    } else if (!isLeaf(p) && (isLeaf(q) || extent(p) >= extent(q))) {
      next(both(p.left, b));
      next(both(p.right, b));
    } else {
      next(both(a, q.left));
      next(both(a, q.right));
    }
  };
  // The walk's first levels, in its order, until there are enough pairs of nodes to share among
  // the threads (and the leaves met on the way, in their places); then each of those walked on its
  // own (depth first, as one walk would), and their leaves joined in that order: the same list,
  // whatever the number of threads.
  struct Task {
    std::uint64_t pair;
    bool leaf;  // a pair of leaves already
  };
  std::vector<Task> tasks, wider;
  std::int64_t tests = 0;
  if (!nodes_.empty()) tasks.push_back({both(0, 0), false});
  for (bool grew = true; grew && tasks.size() < kWalkTasks;) {
    grew = false;
    wider.clear();
    for (const Task& task : tasks) {
      if (task.leaf) {
        wider.push_back(task);
        continue;
      }
      grew = true;
      step(
          task.pair,
          [&](std::uint64_t leaf) {
            wider.push_back({leaf, true});
          },
          [&](std::uint64_t pair) {
            wider.push_back({pair, false});
          },
          tests);
    }
    tasks.swap(wider);
  }
  walked_.resize(tasks.size());
  walkTests_.assign(static_cast<std::size_t>(workers.threads()), 0);
  workers.runShared(
      tasks.size(), 1,
      [&](std::size_t begin, std::size_t end, int thread) {
        std::int64_t compared = 0;
        std::uint64_t children[3];
        for (std::size_t t = begin; t < end; ++t) {
          std::vector<std::uint64_t>& out = walked_[t];
          out.clear();
          if (tasks[t].leaf) {
            out.push_back(tasks[t].pair);
            continue;
          }
          std::vector<std::uint64_t> stack{tasks[t].pair};
          while (!stack.empty()) {
            const std::uint64_t pair = stack.back();
            stack.pop_back();
            int count = 0;
            step(
                pair, [&](std::uint64_t leaf) { out.push_back(leaf); },
                [&](std::uint64_t next) { children[count++] = next; }, compared);
            // Last in, first out: the first to look at goes on top.
            while (count > 0) stack.push_back(children[--count]);
          }
        }
        walkTests_[static_cast<std::size_t>(thread)] += compared;
      },
      1);
  leafPairs_.clear();
  for (const std::vector<std::uint64_t>& out : walked_) leafPairs_.insert(leafPairs_.end(), out.begin(), out.end());
  // The parts' lists go once joined: kept, they held half as much again as the joined list (a
  // crumpled pile's search at 64 x 64: 810 bytes a particle).
  for (std::vector<std::uint64_t>& out : walked_) std::vector<std::uint64_t>().swap(out);
  for (const std::int64_t compared : walkTests_) tests += compared;

  // Their primitives, in parallel: blocks of leaf pairs to whichever thread is free (a crumpled
  // pile's leaves find far more than a flat sheet's: in even runs, one thread had most of the work
  // and two threads were no faster than one), each block's pairs in its own lists, joined in the
  // blocks' order, so the same whatever the number of threads.
  const auto threads = static_cast<std::size_t>(workers.threads());
  const std::size_t blocks = (leafPairs_.size() + kLeafPairBlock - 1) / kLeafPairBlock;
  found_.resize(2 * blocks);
  boxTests_.assign(threads, 0);
  for (std::vector<Pair>& found : found_) found.clear();
  workers.runShared(
      leafPairs_.size(), kLeafPairBlock,
      [&](std::size_t begin, std::size_t end, int thread) {
        // The block's lists and count on this thread's stack while it fills them: the lists' headers
        // and the counts of two threads share cache lines, and writing them at every pair and every
        // test made two threads no faster than one.
        const std::size_t block = begin / kLeafPairBlock;
        std::vector<Pair> vertexTriangle, edgeEdge;
        vertexTriangle.swap(found_[2 * block]);
        edgeEdge.swap(found_[2 * block + 1]);
        std::int64_t compared = 0;
        // The vertices of leaf `from` against the triangles of leaf `to`: not those it is a corner of.
        const auto vertices = [&](std::uint32_t from, std::uint32_t to) {
          const Node& other = nodes_[leafNode_[to]];
          for (std::uint32_t i = leafVertexStart_[from]; i < leafVertexStart_[from + 1]; ++i) {
            const std::uint32_t v = leafVertices_[i];
            const glm::vec3 lo = boxLower_[v], hi = boxUpper_[v];
            ++compared;
            if (from != to && !overlap(lo, hi, other.lower, other.upper)) continue;
            for (std::uint32_t j = leafTriangleStart_[to]; j < leafTriangleStart_[to + 1]; ++j) {
              const std::uint32_t t = leafTriangles_[j];
              ++compared;
              if (overlap(lo, hi, boxLower_[n + t], boxUpper_[n + t])) listVertexTriangle(v, t, vertexTriangle);
            }
          }
        };
        for (std::size_t i = begin; i < end; ++i) {
          const auto l = static_cast<std::uint32_t>(leafPairs_[i] >> 32), m = static_cast<std::uint32_t>(leafPairs_[i]);
          vertices(l, m);
          if (l != m) vertices(m, l);
          // Edge pairs that share no end, each once: within one leaf, the later against the earlier.
          const Node& other = nodes_[leafNode_[m]];
          for (std::uint32_t i0 = leafEdgeStart_[l]; i0 < leafEdgeStart_[l + 1]; ++i0) {
            const std::uint32_t e = leafEdges_[i0];
            const glm::vec3 lo = boxLower_[n + nt + e], hi = boxUpper_[n + nt + e];
            ++compared;
            if (l != m && !overlap(lo, hi, other.lower, other.upper)) continue;
            for (std::uint32_t i1 = l == m ? i0 + 1 : leafEdgeStart_[m]; i1 < leafEdgeStart_[m + 1]; ++i1) {
              const std::uint32_t f = leafEdges_[i1];
              ++compared;
              if (overlap(lo, hi, boxLower_[n + nt + f], boxUpper_[n + nt + f])) listEdgeEdge(e, f, edgeEdge);
            }
          }
        }
        found_[2 * block].swap(vertexTriangle);
        found_[2 * block + 1].swap(edgeEdge);
        boxTests_[static_cast<std::size_t>(thread)] += compared;
      },
      64);
  pairs_.clear();
  for (std::size_t k = 0; k < 2; ++k) {
    for (std::size_t b = 0; b < blocks; ++b)
      pairs_.insert(pairs_.end(), found_[2 * b + k].begin(), found_[2 * b + k].end());
  }
  // The blocks' lists go once joined: kept, they held as much again as the pairs.
  for (std::vector<Pair>& found : found_) std::vector<Pair>().swap(found);
  for (const std::int64_t compared : boxTests_) tests += compared;
  stats_.boxTests += tests;
}

void SelfContact::refresh(const std::vector<std::uint32_t>& strays, Workers& workers) {
  // Each stray particle's box: its motion in this substep as it now is, grown as a search grows
  // it. The triangles and edges it is a corner of are boxed again; every pair of these primitives
  // goes, and each is paired anew with whatever its box overlaps, as a search would pair it. The
  // other pairs a search would find are already listed: their boxes are as they were.
  const std::size_t n = x_.size(), nt = triangles_.size(), ne = edges_.size();
  ++stats_.refreshes;
  affected_.assign(n + nt + ne, 0);
  for (const std::uint32_t i : strays) {
    affected_[i] = 1;
    lower_[i] = glm::min(x0_[i], x_[i]) - grow_;
    upper_[i] = glm::max(x0_[i], x_[i]) + grow_;
    boxLower_[i] = below(lower_[i]);
    boxUpper_[i] = above(upper_[i]);
    for (std::uint32_t k = vertexStart_[i]; k < vertexStart_[i + 1]; ++k) affected_[n + vertexTriangles_[k]] = 1;
  }
  for (std::size_t e = 0; e < ne; ++e) {
    if (affected_[edges_[e][0]] || affected_[edges_[e][1]]) affected_[n + nt + e] = 1;
  }
  for (std::size_t k = n; k < n + nt + ne; ++k) {
    if (affected_[k]) boxPrimitive(k);
  }
  std::erase_if(pairs_, [&](const Pair& p) {
    return p.edges ? affected_[n + nt + p.first] || affected_[n + nt + p.second]
                   : affected_[p.first] || affected_[n + p.second];
  });
  fitTree();

  // The primitives to pair again, in the order a search lists their pairs: the stray vertices, the
  // triangles with a stray corner, the edges with a stray end. Shared among the workers in blocks,
  // each block's pairs in its own list, joined in the blocks' order: the same pairs in the same
  // order whatever the number of threads.
  refreshed_.clear();
  for (std::size_t k = 0; k < n + nt + ne; ++k) {
    if (affected_[k]) refreshed_.push_back(static_cast<std::uint32_t>(k));
  }
  const std::size_t blocks = (refreshed_.size() + kRefreshBlock - 1) / kRefreshBlock;
  found_.resize(blocks);
  boxTests_.assign(static_cast<std::size_t>(workers.threads()), 0);
  workers.runShared(
      refreshed_.size(), kRefreshBlock,
      [&](std::size_t begin, std::size_t end, int thread) {
        std::vector<Pair> found;
        found.swap(found_[begin / kRefreshBlock]);
        found.clear();
        std::int64_t compared = 0;
        // The block's primitives in clusters of neighbours (in the order of their own leaves, so near
        // one another at rest; a primitive joins the cluster before it while the box around them
        // all stays within kClusterSpread of its largest member's), each cluster's tree walked once
        // with that box, for the leaves it overlaps, in the tree's order. A primitive's leaves are
        // those of its cluster its own box overlaps: the same leaves in the same order as a walk of
        // its own (a node's box holds its children's, so a leaf its box overlaps was reached), for a
        // tenth of the walking (a stray particle's triangles and edges walked the same nodes).
        const std::size_t count = end - begin;
        std::vector<std::uint32_t> order(count), cluster(count), walk;
        std::vector<std::uint32_t> candidateStart{0}, candidates;
        for (std::size_t i = 0; i < count; ++i) order[i] = static_cast<std::uint32_t>(i);
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
          const std::uint32_t la = primitiveLeaf_[refreshed_[begin + a]], lb = primitiveLeaf_[refreshed_[begin + b]];
          return la < lb || (la == lb && a < b);
        });
        const auto extent = [](const glm::vec3& lo, const glm::vec3& hi) {
          const glm::vec3 size = hi - lo;
          return size.x + size.y + size.z;
        };
        const auto walkCluster = [&](const glm::vec3& lo, const glm::vec3& hi) {
          walk.clear();
          if (!nodes_.empty()) walk.push_back(0);
          while (!walk.empty()) {
            const Node& node = nodes_[walk.back()];
            walk.pop_back();
            ++compared;
            if (!overlap(node.lower, node.upper, lo, hi)) continue;
            if (node.right == kNone) {
              candidates.push_back(node.left);
            } else {
              walk.push_back(node.right);
              walk.push_back(node.left);
            }
          }
          candidateStart.push_back(static_cast<std::uint32_t>(candidates.size()));
        };
        glm::vec3 clusterLo{0.0f}, clusterHi{0.0f};
        float largest = 0.0f;
        for (std::size_t j = 0; j < count; ++j) {
          const std::uint32_t k = refreshed_[begin + order[j]];
          const glm::vec3 lo = boxLower_[k], hi = boxUpper_[k];
          const float own = extent(lo, hi);
          const glm::vec3 unionLo = glm::min(clusterLo, lo), unionHi = glm::max(clusterHi, hi);
          // (Whatever the clusters, a primitive meets the leaves a walk of its own would: a torn
          // primitive's empty box or a NaN one overlaps none of its cluster's.)
          if (j > 0 && extent(unionLo, unionHi) <= kClusterSpread * std::max(largest, own)) {
            clusterLo = unionLo;
            clusterHi = unionHi;
            largest = std::max(largest, own);
          } else {
            if (j > 0) walkCluster(clusterLo, clusterHi);
            clusterLo = lo;
            clusterHi = hi;
            largest = own;
          }
          cluster[order[j]] = static_cast<std::uint32_t>(candidateStart.size() - 1);
        }
        if (count > 0) walkCluster(clusterLo, clusterHi);
        // The leaves whose boxes overlap box k, in the tree's order (i: its place in the block).
        const auto leaves = [&](std::size_t k, std::size_t i, auto&& visit) {
          const std::uint32_t c = cluster[i];
          for (std::uint32_t j = candidateStart[c]; j < candidateStart[c + 1]; ++j) {
            const std::uint32_t leaf = candidates[j];
            const Node& node = nodes_[leafNode_[leaf]];
            ++compared;
            if (overlap(node.lower, node.upper, boxLower_[k], boxUpper_[k])) visit(leaf);
          }
        };
        // Listed as a search lists them, far (measured by the fail-safe if it must be), and marked new.
        const auto vertexTriangle = [&](std::uint32_t v, std::uint32_t t) {
          ++compared;
          if (overlap(boxLower_[v], boxUpper_[v], boxLower_[n + t], boxUpper_[n + t])) listVertexTriangle(v, t, found);
        };
        // A stray vertex against every triangle; a triangle with a stray corner against every vertex
        // but the stray ones (paired from their side); an edge with a stray end against every edge,
        // and against another such edge once.
        for (std::size_t i = begin; i < end; ++i) {
          const std::uint32_t k = refreshed_[i];
          if (k < n) {
            leaves(k, i - begin, [&](std::uint32_t leaf) {
              for (std::uint32_t j = leafTriangleStart_[leaf]; j < leafTriangleStart_[leaf + 1]; ++j)
                vertexTriangle(k, leafTriangles_[j]);
            });
          } else if (k < n + nt) {
            const auto t = static_cast<std::uint32_t>(k - n);
            leaves(k, i - begin, [&](std::uint32_t leaf) {
              for (std::uint32_t j = leafVertexStart_[leaf]; j < leafVertexStart_[leaf + 1]; ++j) {
                if (!affected_[leafVertices_[j]]) vertexTriangle(leafVertices_[j], t);
              }
            });
          } else {
            const auto e = static_cast<std::uint32_t>(k - n - nt);
            const glm::vec3 lo = boxLower_[k], hi = boxUpper_[k];
            leaves(k, i - begin, [&](std::uint32_t leaf) {
              for (std::uint32_t j = leafEdgeStart_[leaf]; j < leafEdgeStart_[leaf + 1]; ++j) {
                const std::uint32_t f = leafEdges_[j];
                if (f == e || (affected_[n + nt + f] && f < e)) continue;
                ++compared;
                if (overlap(lo, hi, boxLower_[n + nt + f], boxUpper_[n + nt + f])) listEdgeEdge(e, f, found);
              }
            });
          }
        }
        found_[begin / kRefreshBlock].swap(found);
        boxTests_[static_cast<std::size_t>(thread)] += compared;
      },
      1);
  for (std::size_t b = 0; b < blocks; ++b) pairs_.insert(pairs_.end(), found_[b].begin(), found_[b].end());
  for (std::vector<Pair>& found : found_) std::vector<Pair>().swap(found);
  std::int64_t compared = 0;
  for (const std::int64_t tests : boxTests_) compared += tests;
  stats_.boxTests += compared;
}

const std::vector<std::uint32_t>& SelfContact::strays(const std::vector<std::uint32_t>* candidates, Real margin) {
  strays_.clear();
  const auto look = [&](std::uint32_t i) {
    const Vec3 lo = lower_[i] + margin, hi = upper_[i] - margin;
    for (const Vec3& x : {x0_[i], x_[i]}) {
      if (glm::any(glm::lessThan(x, lo)) || glm::any(glm::greaterThan(x, hi))) {
        strays_.push_back(i);
        return;
      }
    }
  };
  if (candidates) {
    for (const std::uint32_t i : *candidates) look(i);
  } else {
    for (std::uint32_t i = 0; i < x_.size(); ++i) look(i);
  }
  return strays_;
}

bool SelfContact::keepPairs(const std::vector<std::uint32_t>* candidates, Real distance, Workers& workers) {
  if (strays(candidates, 0.0).empty()) return false;
  if (strays_.size() * kStraysForSearch > x_.size()) {
    findPairs(distance, 1.0, workers);
    measurePairs(distance, workers);
  } else {
    refresh(strays_, workers);
  }
  return true;
}

Real SelfContact::proven(const Pair& p) const {
  // Along a fixed line, each corner's position moves by no more than the corner does: each side's
  // reach along it grows by its farthest-gone corner's reach_, and the gap shrinks by the two.
  const std::size_t nt = triangles_.size();
  const Real first = p.edges ? primitiveReach_[nt + p.first] : reach_[p.first];
  return static_cast<Real>(p.apart) - first - primitiveReach_[(p.edges ? nt : 0) + p.second];
}

void SelfContact::reachOfPrimitives(Workers& workers) {
  const std::size_t nt = triangles_.size(), ne = edges_.size();
  primitiveReach_.resize(nt + ne);
  workers.run(
      nt + ne,
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t k = begin; k < end; ++k) {
          Real most = 0.0;
          if (k < nt) {
            for (int c = 0; c < 3; ++c) most = std::max(most, reach_[triangles_[k][c]]);
          } else {
            for (int c = 0; c < 2; ++c) most = std::max(most, reach_[edges_[k - nt][c]]);
          }
          primitiveReach_[k] = most;
        }
      },
      4096);
}

Real SelfContact::separationAlong(const std::array<std::uint32_t, 4>& v, int split, const Vec3& axis) const {
  // The hull of one side's corners at x0 and at x against the other's, along the axis. Apart there,
  // they are apart all along the straight paths from x0 to x (each corner's path lies between its
  // two ends).
  Real lo[2], hi[2];
  for (int side = 0; side < 2; ++side) {
    lo[side] = std::numeric_limits<Real>::max();
    hi[side] = std::numeric_limits<Real>::lowest();
  }
  for (int k = 0; k < 4; ++k) {
    const int side = k < split ? 0 : 1;
    const Real a = glm::dot(x0_[v[k]], axis), b = glm::dot(x_[v[k]], axis);
    lo[side] = std::min({lo[side], a, b});
    hi[side] = std::max({hi[side], a, b});
  }
  // The rounding of the dot products grows with the coordinates, not with the projections: room for
  // the largest coordinate of any particle (coordinates_).
  const Real scale = coordinates_ * (std::abs(axis.x) + std::abs(axis.y) + std::abs(axis.z));
  // Along the axis as it is (not of unit length): the gap over its length, less room for rounding.
  const Real length = glm::length(axis);
  const Real gap = std::max(lo[0] - hi[1], lo[1] - hi[0]) - 1e-12 * scale;
  const Real apart = gap / length;
  // Nothing unless every figure is finite (min and max pass a NaN by).
  if (!(length > 0.0) || !std::isfinite(apart + lo[0] + hi[0] + lo[1] + hi[1]))
    return -std::numeric_limits<Real>::infinity();
  return apart;
}

Real SelfContact::separation(const Pair& p) const {
  // Along the line between the two primitives' centres at x0: cheap, and enough for most.
  const std::array<std::uint32_t, 4> v = corners(p);
  const Vec3 centres = p.edges ? (x0_[v[0]] + x0_[v[1]]) * 0.5 - (x0_[v[2]] + x0_[v[3]]) * 0.5
                               : x0_[v[0]] - (x0_[v[1]] + x0_[v[2]] + x0_[v[3]]) * (1.0 / 3.0);
  return separationAlong(v, p.edges ? 2 : 1, centres);
}

SelfContact::Contact SelfContact::measure(Pair& pair, Real distance) const {
  const std::array<std::uint32_t, 4> v = corners(pair);
  Contact contact;
  const Weights weights = pair.edges ? edgeEdgeWeights(x0_[v[0]], x0_[v[1]], x0_[v[2]], x0_[v[3]])
                                     : vertexTriangleWeights(x0_[v[0]], x0_[v[1]], x0_[v[2]], x0_[v[3]]);
  for (int k = 0; k < 4; ++k) {
    contact.c[k] = weights.c[k];
    contact.v[k] = v[k];
  }
  contact.edges = pair.edges;
  const Vec3 gap = between(weights, x0_[v[0]], x0_[v[1]], x0_[v[2]], x0_[v[3]]);
  contact.gap0 = glm::length(gap);
  contact.normal = contact.gap0 > kCoincident ? gap / contact.gap0 : Vec3{0.0};
  contact.push = 0.0;
  // How far apart the pair keeps: `distance`, or less for parts of one cloth closer than that at rest.
  // (Which it is, the pair keeps from its first measure: the rest shape and the distance stay while
  // it does, as a change of either finds the pairs again.)
  contact.target = distance;
  if (pair.rest != kRestApart) {
    Real rest = distance;
    if (clothOf_[v[0]] == clothOf_[v[2]]) {
      const Weights w = pair.edges ? edgeEdgeWeights(rest_[v[0]], rest_[v[1]], rest_[v[2]], rest_[v[3]])
                                   : vertexTriangleWeights(rest_[v[0]], rest_[v[1]], rest_[v[2]], rest_[v[3]]);
      rest = glm::length(between(w, rest_[v[0]], rest_[v[1]], rest_[v[2]], rest_[v[3]]));
    }
    pair.rest = rest < distance ? kRestNear : kRestApart;
    contact.target = std::min(distance, rest);
  }
  // The two sides of a closed seam (a tear's or a cut's copies, still on the same points) have no
  // line between them to be kept apart along: they part along the line from the second side's
  // triangles to the first's, and by kSeamApart. Without it the sweeps drew a seam lying flat on the
  // table into an overlap of its own two sides, which the fail-safe sent back to x0 every substep
  // after: a shred of the desk's tear lay frozen with a link 64 % long (docs/design.md).
  if (!(contact.gap0 > kCoincident) && pair.rest == kRestNear) {
    // The centre of a side's triangles at x0; none for a particle in no triangle (a chain's).
    const auto centreOf = [&](const std::uint32_t* triangles, std::size_t count) -> std::optional<Vec3> {
      Vec3 sum{0.0};
      Real used = 0.0;
      for (std::size_t i = 0; i < count; ++i) {
        if (triangles[i] == kNone) continue;
        const glm::uvec3 t = triangles_[triangles[i]];
        sum += x0_[t[0]] + x0_[t[1]] + x0_[t[2]];
        used += 3.0;
      }
      if (!(used > 0.0)) return std::nullopt;
      return sum / used;
    };
    const std::optional<Vec3> first = pair.edges ? centreOf(&edgeTriangles_[2 * pair.first], 2)
                                                 : centreOf(&vertexTriangles_[vertexStart_[pair.first]],
                                                            vertexStart_[pair.first + 1] - vertexStart_[pair.first]);
    const std::optional<Vec3> second =
        pair.edges ? centreOf(&edgeTriangles_[2 * pair.second], 2) : centreOf(&pair.second, 1);
    const Real length = first && second ? glm::length(*first - *second) : 0.0;
    if (length > kCoincident) {
      contact.normal = (*first - *second) / length;
      contact.target = std::max(contact.target, kSeamApart);
    }
  }
  return contact;
}

void SelfContact::measurePairs(Real distance, Workers& workers) {
  // Each pair's closest points at x0, the direction between them, and how far apart they keep;
  // except a pair apart by more than `distance` all through the substep (as the solve found it),
  // which no sweep pushes: it is marked far, and the fail-safe looks at it again at its end.
  // A pair kept from the last measure carries what was proven of it then: where that, less how far
  // its corners went since (at x0 and now), still keeps it apart by more than `distance`, it is far
  // without looking again; and what is left of the proof is what it carries on. The others are
  // looked at along the line between their centres.
  const std::size_t n = x_.size();
  const bool carried = xMeasured_.size() == n;
  reach_.resize(n);
  coordinates_ = 0.0;
  for (std::size_t i = 0; i < n; ++i) coordinates_ = std::max({coordinates_, largest(x0_[i]), largest(x_[i])});
  if (carried) {
    workers.run(
        n,
        [&](std::size_t begin, std::size_t end, int) {
          for (std::size_t i = begin; i < end; ++i) reachOf(static_cast<std::uint32_t>(i), true);
        },
        1024);
    reachOfPrimitives(workers);
  }
  // Two loops cut alike (as many pairs, in as many runs): the first tells each run's far pairs from
  // the others (by what is carried, or along the line between the centres) and counts these; the
  // second measures them into contacts_, each run's from where the runs before it end, in the
  // pairs' order whatever the number of threads. A measured pair the line between its closest points
  // proves far is far after all (what lies side by side, as a lattice's parallel diagonals, is not
  // apart along the centres' line): its slot in contacts_ stays empty (gap0 -1, which no sweep
  // looks at).
  const auto threads = static_cast<std::size_t>(workers.threads());
  std::vector<std::size_t>& near = runNear_;
  near.assign(threads + 1, 0);
  constexpr std::uint32_t kNear = 0;
  workers.run(
      pairs_.size(),
      [&](std::size_t begin, std::size_t end, int thread) {
        std::size_t count = 0;
        for (std::size_t i = begin; i < end; ++i) {
          Pair& pair = pairs_[i];
          Real apart = carried && pair.apart != kUnproven ? proven(pair) : -std::numeric_limits<Real>::infinity();
          if (!(apart > distance)) apart = separation(pair);
          pair.apart = floatBelow(apart);
          pair.contact = apart > distance ? kFar : kNear;
          count += pair.contact == kNear;
        }
        near[static_cast<std::size_t>(thread) + 1] = count;
      },
      1024);
  for (std::size_t t = 0; t < threads; ++t) near[t + 1] += near[t];
  contacts_.resize(near[threads]);
  workers.run(
      pairs_.size(),
      [&](std::size_t begin, std::size_t end, int thread) {
        auto next = static_cast<std::uint32_t>(near[static_cast<std::size_t>(thread)]);
        for (std::size_t i = begin; i < end; ++i) {
          Pair& pair = pairs_[i];
          if (pair.contact == kFar) continue;
          Contact& contact = contacts_[next];
          contact = measure(pair, distance);
          const Real apart = separationAlong(corners(pair), pair.edges ? 2 : 1, contact.normal);
          if (apart > distance) {
            pair.apart = floatBelow(apart);
            pair.contact = kFar;
            contact.gap0 = -1.0;
          } else {
            // Near: it carries the better of its two proofs (the fail-safe reads it), and is
            // measured again next substep all the same.
            pair.apart = std::max(pair.apart, floatBelow(apart));
            pair.contact = next;
          }
          ++next;
        }
      },
      1024);
  // (What the pairs now carry was proven of the particles' paths as they are.)
  x0Measured_ = x0_;
  xMeasured_ = x_;
}

void SelfContact::sweep(Real distance, Real friction, std::vector<ClothRecord>& cloths) {
  const auto gapNow = [&](const Contact& p) {
    Real g = -p.target;
    for (int k = 0; k < 4; ++k) g += p.c[k] * glm::dot(p.normal, x_[p.v[k]]);
    return g;
  };
  // How far each unit the two points must part moves the particles: 1 / sum_k c_k^2 w_k, so that
  // the masses share the move; nothing where that would move a particle more than 1 /
  // kContactLeverage times as far as the points part (a held vertex against a triangle whose only
  // free corner has a small weight there: the pair is then left to the fail-safe rather than the
  // corner flung).
  const auto reach = [&](const Contact& p) {
    const Real weight = contact::partingWeight(w_, p);
    return weight > 0.0 ? 1.0 / weight : 0.0;
  };
  const auto facing = [&](const Contact& p) { return contact::facing(x_, p); };
  // The pairs a sweep can push: within one more `distance` of their target now.
  active_.clear();
  for (std::uint32_t i = 0; i < contacts_.size(); ++i) {
    const Contact& p = contacts_[i];
    // (A contact with a line to push along: apart at x0, or a closed seam's two sides.)
    if (p.gap0 >= 0.0 && glm::dot(p.normal, p.normal) > 0.0 && gapNow(p) < distance) active_.push_back(i);
  }
  const std::vector<std::uint32_t>& active = active_;
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    for (const std::uint32_t i : active) {
      Contact& p = contacts_[i];
      const Real g = gapNow(p);
      if (g >= 0.0 || !facing(p)) continue;
      const Real lambda = -g * reach(p);
      if (!(lambda > 0.0)) continue;
      for (int k = 0; k < 4; ++k) x_[p.v[k]] += p.normal * (p.c[k] * w_[p.v[k]] * lambda);
      p.push -= g;
    }
    for (const Plane& plane : planes_) {
      const Real gap = glm::dot(plane.normal, x_[plane.particle]) - plane.offset;
      if (gap < 0.0) {
        x_[plane.particle] -= plane.normal * gap;
        cloths[plane.cloth].work->solver.contactDepth[plane.index] -= gap;
      }
    }
  }
  std::int64_t pushed = 0;
  // What the sweeps pushed, for the next substep's constraint sweeps (SolverScratch::layerContacts).
  for (ClothRecord& each : cloths) each.work->solver.layerContacts.clear();
  for (const std::uint32_t i : active) {
    const Contact& p = contacts_[i];
    if (p.push <= 0.0) continue;
    const std::uint32_t c = clothOf_[p.v[0]];
    if (clothOf_[p.v[1]] != c || clothOf_[p.v[2]] != c || clothOf_[p.v[3]] != c) continue;
    SolverScratch::LayerContact held;
    for (int k = 0; k < 4; ++k) {
      held.v[k] = p.v[k] - clothStart_[c];
      held.c[k] = p.c[k];
    }
    held.normal = p.normal;
    held.target = p.target;
    held.edges = p.edges;
    cloths[c].work->solver.layerContacts.push_back(held);
  }
  for (const std::uint32_t i : active) {
    Contact& p = contacts_[i];
    if (p.push <= 0.0) continue;
    ++pushed;
    if (friction <= 0.0) continue;
    const Real scale = reach(p);
    if (!(scale > 0.0)) continue;
    Vec3 relative{0.0};
    for (int k = 0; k < 4; ++k) relative += (x_[p.v[k]] - x0_[p.v[k]]) * p.c[k];
    const Vec3 tangential = relative - p.normal * glm::dot(p.normal, relative);
    const Real length = glm::length(tangential);
    if (!(length > 0.0)) continue;
    // Coulomb: the tangential motion reduced by mu times the push, but by at most one distance of
    // push a substep. Layers resting on each other take far less (g h^2 and the weight above); a
    // bigger push is the sweep taking back a link the constraints pulled through the other layer
    // (stretched around a fold's edge), not layers pressed together. Counted whole, it held the
    // two layers fast, the link could not slide off the edge, and it stayed stretched: the fold at
    // 64 x 64 ended with a link 2 to 4.6 times its rest length in 3 of 8 runs whose distances
    // differed by 1e-9 of themselves, and at 3 to 6 % in all 8 with the bound.
    const Vec3 change = tangential * (-std::min(friction * std::min(p.push, distance) / length, 1.0) * scale);
    for (int k = 0; k < 4; ++k) x_[p.v[k]] += change * (p.c[k] * w_[p.v[k]]);
  }
  stats_.pushed = pushed;
}

void SelfContact::failSafe(Real distance, Workers& workers) {
  // The boxes must hold every particle's whole motion: where the solve took one beyond its box, the
  // pairs are found again for the motion as it now is.
  const std::size_t n = x_.size();
  keepPairs(nullptr, distance, workers);
  triangleMoved_.assign(triangles_.size(), 0);
  movedTriangles_.clear();
  if (inZone_.size() != n) inZone_.assign(n, 0);
  if (stays_.size() != n) stays_.assign(n, 0);
  bool anyStays = false;                       // a zone stayed at x0 this substep (counted once in the fallbacks)
  std::vector<std::uint32_t>& stuck = stuck_;  // per round: the zones of pairs that joined nothing
  std::vector<std::pair<std::uint32_t, std::uint32_t>>& everPassing = everPassing_;  // every round's, in order
  everPassing.clear();
  zone_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) zone_[i] = i;
  const auto root = [&](std::uint32_t i) {
    while (zone_[i] != i) i = zone_[i] = zone_[zone_[i]];
    return i;
  };
  const std::vector<Vec3> solved = x_;  // each particle's motion as the contacts left it
  // The exact triangles the tests need, each made once: at x0 once a substep, at x again only where
  // a zone moved a corner. `slot`: per triangle, where in `made` it is (kNone: not yet).
  struct Made {
    std::vector<std::uint32_t>& slot;
    std::vector<std::optional<exact::Triangle>>& made;
    std::vector<std::uint32_t>& which;  // the triangles made, to clear their slots
  };
  Made at0{slot0_, made0_, which0_}, atX{slotX_, madeX_, whichX_};
  for (Made* m : {&at0, &atX}) {
    m->slot.resize(triangles_.size(), kNone);
    m->made.clear();
    m->which.clear();
  }
  const auto make = [&](Made& m, const std::vector<Vec3>& x, std::uint32_t t) {
    if (m.slot[t] == kNone) {
      const glm::uvec3 c = triangles_[t];
      m.slot[t] = static_cast<std::uint32_t>(m.made.size());
      m.made.push_back(exact::makeTriangle(x[c[0]], x[c[1]], x[c[2]], {c[0], c[1], c[2]}));
      m.which.push_back(t);
    }
  };
  // Whether triangles a and b intersect. Particles of one cloth at one grid point are one corner,
  // as the counter has them (countIntersections): the copies a tear makes, before the seam opens.
  const auto through = [&](const std::optional<exact::Triangle>& a, const std::optional<exact::Triangle>& b) {
    if (!a || !b) return false;
    for (int axis = 0; axis < 3; ++axis) {
      if (a->upper[axis] < b->lower[axis] || b->upper[axis] < a->lower[axis]) return false;
    }
    const auto copies = [&](int i, int j) {
      return a->particle[i] != b->particle[j] && a->p[i] == b->p[j] &&
             clothOf_[a->particle[i]] == clothOf_[b->particle[j]];
    };
    bool any = false;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) any = any || copies(i, j);
    }
    if (!any) return exact::intersect(*a, *b);
    exact::Triangle unified = *b;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (copies(i, j)) unified.particle[j] = a->particle[i];
      }
    }
    return exact::intersect(*a, unified);
  };
  // Neighbours across an edge intersect only folded flat onto each other (exact::intersect), but a
  // fold pressed through its closed position within the substep passes one through the other all
  // the same: the free corner d of t goes through s. Seen at the ends: d on opposite sides of the
  // plane of s at x0 and at x (exact), and, where it crossed that plane (the signed volume taken as
  // linear in between), on the side of the shared edge where s's own free corner c is (the fold
  // closed, not opened through flat); a fold flat at x0 aside (kFlatFold). `other`: the corner of t
  // that s does not have (-1 when they share no edge).
  const auto other = [&](std::uint32_t s, std::uint32_t t) {
    const glm::uvec3 a = triangles_[s], b = triangles_[t];
    int shared = 0, j = -1;
    for (int k = 0; k < 3; ++k) {
      if (b[k] == a[0] || b[k] == a[1] || b[k] == a[2]) {
        ++shared;
      } else {
        j = k;
      }
    }
    return shared == 2 ? j : -1;
  };
  // The corners: a and b shared, c of s alone, d of t alone.
  const auto fold = [&](std::uint32_t s, std::uint32_t t, int j) {
    const glm::uvec3 a = triangles_[s];
    int i = 0;
    while (a[i] == triangles_[t][0] || a[i] == triangles_[t][1] || a[i] == triangles_[t][2]) ++i;
    return std::array<std::uint32_t, 4>{a[(i + 1) % 3], a[(i + 2) % 3], a[i], triangles_[t][j]};
  };
  const auto volume = [](const std::vector<Vec3>& x, const std::array<std::uint32_t, 4>& q) {
    const Vec3 o = x[q[0]];
    return glm::dot(glm::cross(x[q[1]] - o, x[q[2]] - o), x[q[3]] - o);
  };
  // Whether d crossed the plane of s, in doubles: for the parallel look, before the exact one (a
  // crossing too close to call there is a fold already flat, which exact::intersect judges).
  const auto mayCross = [&](std::uint32_t s, std::uint32_t t, int j) {
    const std::array<std::uint32_t, 4> q = fold(s, t, j);
    return volume(x0_, q) * volume(x_, q) < 0.0;
  };
  const auto wrapped = [&](std::uint32_t s, std::uint32_t t) {
    const int j = other(s, t);
    if (j < 0) return false;
    make(at0, x0_, s);
    make(at0, x0_, t);
    make(atX, x_, s);
    make(atX, x_, t);
    const std::optional<exact::Triangle>&s0 = made0_[slot0_[s]], &t0 = made0_[slot0_[t]];
    const std::optional<exact::Triangle>&s1 = madeX_[slotX_[s]], &t1 = madeX_[slotX_[t]];
    if (!s0 || !t0 || !s1 || !t1) return false;
    const int before = exact::orient3(s0->p[0], s0->p[1], s0->p[2], t0->p[j]);
    const int after = exact::orient3(s1->p[0], s1->p[1], s1->p[2], t1->p[j]);
    if (before * after >= 0) return false;
    const std::array<std::uint32_t, 4> q = fold(s, t, j);
    const Real v0 = volume(x0_, q), v1 = volume(x_, q);
    // A fold lying flat at x0 had its corner on no side of the other.
    const Vec3 o0 = x0_[q[0]];
    const Real size = glm::length(x0_[q[1]] - o0) * glm::length(x0_[q[2]] - o0) * glm::length(x0_[q[3]] - o0);
    if (!(std::abs(v0) > kFlatFold * size)) return false;
    // Where it crossed: the signed volume, cubic in time as the four corners move straight.
    const Vec3 e0 = x0_[q[1]] - o0, u0 = x0_[q[2]] - o0, w0 = x0_[q[3]] - o0;
    const Vec3 moved = x_[q[0]] - o0;
    const Vec3 de = x_[q[1]] - x0_[q[1]] - moved, du = x_[q[2]] - x0_[q[2]] - moved, dw = x_[q[3]] - x0_[q[3]] - moved;
    const Vec3 eu = glm::cross(e0, u0), mixed = glm::cross(e0, du) + glm::cross(de, u0), dd = glm::cross(de, du);
    std::array<Real, 3> times{};
    int crossings = signChangesIn01({glm::dot(eu, w0), glm::dot(eu, dw) + glm::dot(mixed, w0),
                                     glm::dot(mixed, dw) + glm::dot(dd, w0), glm::dot(dd, dw)},
                                    times);
    if (crossings == 0) {  // too close to call in doubles: where a straight guess puts it
      times[0] = v0 != v1 ? std::clamp(v0 / (v0 - v1), Real{0.0}, Real{1.0}) : Real{0.5};
      crossings = 1;
    }
    // Closed through it, not opened through flat: d on the side of the shared edge where c is.
    for (int k = 0; k < crossings; ++k) {
      const Real at = times[static_cast<std::size_t>(k)];
      const auto then = [&](std::uint32_t i) { return x0_[i] + at * (x_[i] - x0_[i]); };
      const Vec3 o = then(q[0]), e = then(q[1]) - o, u = then(q[2]) - o, v = then(q[3]) - o;
      if (glm::dot(u, v) * glm::dot(e, e) - glm::dot(u, e) * glm::dot(v, e) > 0.0) return true;
    }
    return false;
  };
  // The triangles the fail-safe tests for a pair: around its vertex against its triangle, or those
  // on its first edge against those on its second.
  const auto eachTest = [&](const Pair& p, auto&& f) {
    if (p.edges) {
      for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) {
          const std::uint32_t s = edgeTriangles_[2 * p.first + i], t = edgeTriangles_[2 * p.second + j];
          if (s != kNone && t != kNone) f(s, t);
        }
      }
    } else {
      for (std::uint32_t k = vertexStart_[p.first]; k < vertexStart_[p.first + 1]; ++k)
        f(vertexTriangles_[k], p.second);
    }
  };
  std::vector<std::pair<std::uint32_t, std::uint32_t>> passing;
  std::vector<std::uint32_t> members;  // particles in a zone of more than one
  std::vector<Vec3> sum;               // per zone root: mass-weighted motion
  std::vector<Real> weight;
  std::vector<std::uint64_t>& tests = tests_;
  std::vector<std::uint8_t>& hits = hits_;
  // Every round but the last joins two zones or more: at most one round a particle.
  bool everyPair = true;  // test every pair this round (the first, or the pairs were found again)
  for (std::uint32_t round = 1;; ++round) {
    tests.clear();
    // How far each particle went since the pairs were measured (those a zone moved, after the
    // first round, unless the pairs were measured again).
    // And the largest coordinate: the contacts' sweep and a zone's move may take a particle past it.
    if (everyPair) {
      reach_.resize(n);
      for (std::uint32_t i = 0; i < n; ++i) {
        reachOf(i, false);
        coordinates_ = std::max(coordinates_, largest(x_[i]));
      }
    } else {
      for (const std::uint32_t i : members) {
        reachOf(i, false);
        coordinates_ = std::max(coordinates_, largest(x_[i]));
      }
    }
    reachOfPrimitives(workers);
    // The pairs, in parallel: each run's tests and the far pairs it measured in its own lists,
    // joined in the runs' order (the same whatever the number of threads).
    const auto threads = static_cast<std::size_t>(workers.threads());
    // (Every thread's lists emptied here: a loop over fewer pairs than a thread's share runs on
    // fewer threads, and the others' lists would still hold an earlier round's.)
    scanTests_.resize(threads);
    scanContacts_.resize(threads);
    for (std::vector<std::uint64_t>& found : scanTests_) found.clear();
    for (auto& measured : scanContacts_) measured.clear();
    scanTested_.assign(threads, 0);
    if (!everyPair) primitivesMoved();
    workers.run(
        pairs_.size(),
        [&](std::size_t begin, std::size_t end, int thread) {
          const auto t = static_cast<std::size_t>(thread);
          std::vector<std::uint64_t> found;  // (on the thread's stack while it is filled, as in findPairs)
          std::vector<std::pair<std::uint32_t, Contact>> measured;
          found.swap(scanTests_[t]);  // (emptied before the loop)
          measured.swap(scanContacts_[t]);
          std::int64_t tested = 0;
          for (std::size_t i = begin; i < end; ++i) {
            Pair& p = pairs_[i];
            // After the first round, only pairs whose tests (eachTest) a zone's move changed: where
            // the pair has tests, and one of their triangles moved.
            if (!everyPair && !(p.edges ? primitiveMoved_[n + p.first] + primitiveMoved_[n + p.second] >= 4
                                        : primitiveMoved_[p.first] == 3 ||
                                              (primitiveMoved_[p.first] != 0 && triangleMoved_[p.second])))
              continue;
            // Proven apart all the way: by what the last measure proved, less how far its corners
            // went since; along the line between the centres (a far pair, or a near one whose
            // corners moved apart); or by the gap at x0 against the corners' relative motion.
            if (p.apart != kUnproven && proven(p) > kProofMargin) continue;
            const bool far = p.contact == kFar;
            Real gap0;
            if (far) {
              if (apartAlongCentres(p, kProofMargin)) continue;
              measured.push_back({static_cast<std::uint32_t>(i), measure(p, distance)});
              gap0 = measured.back().second.gap0;
            } else {
              gap0 = contacts_[p.contact].gap0;
            }
            // Along the line between the closest points at x0 (the contact's normal).
            const Contact& contact = far ? measured.back().second : contacts_[p.contact];
            if (separationAlong(corners(p), p.edges ? 2 : 1, contact.normal) > kProofMargin) continue;
            // The largest relative motion of a corner of one against a corner of the other.
            Real m = 0.0;
            const int split = p.edges ? 2 : 1;
            const std::array<std::uint32_t, 4> v = corners(p);
            for (int a = 0; a < split; ++a) {
              for (int b = split; b < 4; ++b) {
                const Vec3 d = (x_[v[a]] - x0_[v[a]]) - (x_[v[b]] - x0_[v[b]]);
                m = std::max(m, glm::dot(d, d));
              }
            }
            if (gap0 > std::sqrt(m) + kProofMargin || (!far && apartAlongCentres(p, kProofMargin))) continue;
            ++tested;
            eachTest(p, [&](std::uint32_t s, std::uint32_t u) {
              found.push_back((static_cast<std::uint64_t>(std::min(s, u)) << 32) | std::max(s, u));
            });
          }
          scanTests_[t].swap(found);
          scanContacts_[t].swap(measured);
          scanTested_[t] = tested;
        },
        1024);
    for (std::size_t t = 0; t < threads; ++t) {
      for (const auto& [i, contact] : scanContacts_[t]) {
        pairs_[i].contact = static_cast<std::uint32_t>(contacts_.size());
        contacts_.push_back(contact);
      }
      tests.insert(tests.end(), scanTests_[t].begin(), scanTests_[t].end());
      stats_.tested += scanTested_[t];
    }
    // Each pair of triangles once (pairs of primitives share them), in order.
    std::sort(tests.begin(), tests.end());
    tests.erase(std::unique(tests.begin(), tests.end()), tests.end());
    stats_.triangleTests += static_cast<std::int64_t>(tests.size());
    for (const std::uint64_t key : tests) {
      make(atX, x_, static_cast<std::uint32_t>(key >> 32));
      make(atX, x_, static_cast<std::uint32_t>(key));
    }
    hits.assign(tests.size(), 0);
    workers.run(
        tests.size(),
        [&](std::size_t begin, std::size_t end, int) {
          for (std::size_t i = begin; i < end; ++i) {
            const std::uint64_t key = tests[i];
            const auto s = static_cast<std::uint32_t>(key >> 32), t = static_cast<std::uint32_t>(key);
            const int j = other(s, t);
            hits[i] = through(madeX_[slotX_[s]], madeX_[slotX_[t]]) || (j >= 0 && mayCross(s, t, j));
          }
        },
        256);
    // Of those that intersect now, the ones that did not at x0; of neighbours, the ones whose fold went through.
    passing.clear();
    for (std::size_t i = 0; i < tests.size(); ++i) {
      if (!hits[i]) continue;
      const auto s = static_cast<std::uint32_t>(tests[i] >> 32), t = static_cast<std::uint32_t>(tests[i]);
      make(at0, x0_, s);
      make(at0, x0_, t);
      const bool now = through(madeX_[slotX_[s]], madeX_[slotX_[t]]);
      if (now ? !through(made0_[slot0_[s]], made0_[slot0_[t]]) : wrapped(s, t)) passing.push_back({s, t});
    }
    // Before ending: every pair that passed in an earlier round, tested again as the particles
    // are now. A round's move may leave a pair that still passes where it is (its corners in a
    // zone whose move did not change, while other pairs joined), and the next round tests only the
    // triangles that moved.
    bool verifying = false;
    if (passing.empty()) {
      for (const auto& [s, t] : everPassing) {
        make(atX, x_, s);
        make(atX, x_, t);
        if (through(madeX_[slotX_[s]], madeX_[slotX_[t]]) || wrapped(s, t)) passing.push_back({s, t});
      }
      if (passing.empty()) break;
      verifying = true;
    } else {
      everPassing.insert(everPassing.end(), passing.begin(), passing.end());
    }
    // A pair's free corners join one zone, which moves as one body from x0 by the mass-weighted mean
    // of its particles' motions: the zone is then as it was at x0, where none of its triangles
    // intersect, and its momentum is kept. Held and pinned corners are obstacles that move as their
    // fingers do, until a pair goes on through one whose free corners already move as one (or has
    // none): then they join the zone too, and it moves as they do on average (they count as
    // infinitely heavy), the finger's grip slipping for the substep.
    bool joined = false;
    stuck.clear();
    for (const auto& [s, t] : passing) {
      std::uint32_t corners[6], zoneOfFree = kNone;
      bool oneZone = true, anyFree = false;
      for (int k = 0; k < 6; ++k) {
        corners[k] = triangles_[k < 3 ? s : t][k % 3];
        if (w_[corners[k]] == 0.0) continue;
        const std::uint32_t r = inZone_[corners[k]] ? root(corners[k]) : kNone;
        oneZone = oneZone && r != kNone && (!anyFree || r == zoneOfFree);
        zoneOfFree = r;
        anyFree = true;
      }
      const bool withHeld = !anyFree || oneZone;
      std::uint32_t r = kNone;
      bool grew = false;  // this pair joined a particle or two zones
      for (const std::uint32_t v : corners) {
        if (w_[v] == 0.0 && !withHeld) continue;
        if (!inZone_[v]) {
          inZone_[v] = 1;
          members.push_back(v);
          grew = true;
        }
        const std::uint32_t q = root(v);
        if (r == kNone) {
          r = q;
        } else if (q != r) {
          zone_[q] = r;
          grew = true;
        }
      }
      joined = joined || grew;
      if (!grew) stuck.push_back(r);
    }
    // A pair that joined nothing goes on through with its corners in one zone already: the zone's
    // move as one body does not clear it (a translation its triangles do not survive on the exact
    // grid, where two layers or the two sides of a fresh tear lie closer than its rounding, or
    // grips that disagree). Once no pair joins anything new, or when the last look above finds the
    // pair still through, that zone stays at x0 for the substep and the rounds go on: what passes
    // through a zone that stays joins it and stays too. Every round joins particles or zones or
    // stops one zone more, so the rounds end; and x0 is clear, so the zones that stay are. Where
    // nothing is left to join or stop (x0 itself not clear on the exact grid), the whole substep
    // goes back to x0, where it began.
    std::vector<std::uint8_t>& stays = staysRoot_;
    stays.assign(n, 0);
    for (const std::uint32_t i : members) stays[root(i)] |= stays_[i];
    bool stopped = false;
    for (const std::uint32_t r : stuck) {
      if (joined && !verifying) break;  // while zones grow, a pair that joined nothing waits
      if (r == kNone || stays[root(r)]) continue;
      stays[root(r)] = 1;
      stopped = true;
    }
    if ((!joined && !stopped) || round > 2 * n + 2) {
      x_ = x0_;
      ++stats_.fallbacks;
      break;
    }
    if (stopped && !anyStays) {
      ++stats_.fallbacks;
      anyStays = true;
    }
    sum.assign(n, Vec3{0.0});
    weight.assign(n, 0.0);
    std::vector<std::uint8_t>& heavy = heavy_;
    heavy.assign(n, 0);
    for (const std::uint32_t i : members) heavy[root(i)] |= w_[i] == 0.0;
    for (const std::uint32_t i : members) {
      const std::uint32_t r = root(i);
      if (heavy[r] && w_[i] != 0.0) continue;
      const Real mass = w_[i] == 0.0 ? 1.0 : 1.0 / w_[i];
      sum[r] += (solved[i] - x0_[i]) * mass;
      weight[r] += mass;
    }
    std::fill(triangleMoved_.begin(), triangleMoved_.end(), 0);
    movedTriangles_.clear();
    for (const std::uint32_t i : members) {
      const std::uint32_t r = root(i);
      stays_[i] = stays[r];
      const Vec3 moved = stays[r] ? x0_[i] : x0_[i] + sum[r] / weight[r];
      if (moved != x_[i]) {
        x_[i] = moved;
        for (std::uint32_t k = vertexStart_[i]; k < vertexStart_[i + 1]; ++k) {
          const std::uint32_t t = vertexTriangles_[k];
          if (!triangleMoved_[t]) movedTriangles_.push_back(t);
          triangleMoved_[t] = 1;
        }
      }
    }
    for (const std::uint32_t t : whichX_) {
      if (triangleMoved_[t]) slotX_[t] = kNone;  // made again where the next round needs it
    }
    // A zone's move may take a member out of its box (the zone's mean motion is larger than the
    // member's own): the pairs then no longer hold every primitive it may meet on its way from x0,
    // so they are found again for the motion as it now is (refreshed, or searched where many
    // left), and all tested. (The wide twist, assets/cases/twist-wide.json, left 3 pairs through
    // each other at 24 x 24 before.)
    everyPair = keepPairs(&members, distance, workers);
  }
  for (Made* m : {&at0, &atX}) {
    for (const std::uint32_t t : m->which) m->slot[t] = kNone;
  }
  stats_.zoned += static_cast<std::int64_t>(members.size());
  for (const std::uint32_t i : members) inZone_[i] = stays_[i] = 0;
}

void SelfContact::primitivesMoved() {
  // Per vertex (its triangles) and per edge (the one or two on it): 0 where it has none, 1 where
  // none of them moved, 3 where one did. An edge pair then has tests, one of whose triangles moved,
  // where its two marks sum to 4 or more (1 + 3, 3 + 3; not 0 + 3).
  const std::size_t n = x_.size(), ne = edges_.size();
  primitiveMoved_.assign(n + ne, 0);
  for (std::uint32_t v = 0; v < n; ++v) primitiveMoved_[v] = vertexStart_[v + 1] > vertexStart_[v] ? 1 : 0;
  for (const std::uint32_t t : movedTriangles_) {
    for (int c = 0; c < 3; ++c) primitiveMoved_[triangles_[t][c]] = 3;
  }
  for (std::uint32_t e = 0; e < ne; ++e) {
    std::uint8_t mark = 0;
    for (int k = 0; k < 2; ++k) {
      const std::uint32_t t = edgeTriangles_[2 * e + k];
      if (t != kNone) mark = std::max<std::uint8_t>(mark, triangleMoved_[t] ? 3 : 1);
    }
    primitiveMoved_[n + e] = mark;
  }
}

void SelfContact::scatter(std::vector<ClothRecord>& cloths) const {
  std::size_t k = 0;
  for (ClothRecord& record : cloths) {
    ParticleState& s = record.cloth.state;
    for (std::size_t i = 0; i < s.position.size(); ++i, ++k) s.position[i] = x_[k];
  }
}

bool SelfContact::prepare(const std::vector<ClothRecord>& cloths, std::uint64_t topologyVersion) {
  std::size_t n = 0, nt = 0;
  for (const ClothRecord& record : cloths) {
    n += record.cloth.state.position.size();
    nt += record.cloth.rest.triangles.size();
  }
  if (topologyVersion == meshVersion_ && n == meshParticles_ && nt == triangles_.size()) return false;
  buildMesh(cloths);
  meshVersion_ = topologyVersion;
  return true;
}

void SelfContact::settle(std::vector<ClothRecord>& cloths, const std::vector<std::vector<Vec3>>& before,
                         const SelfCollisionSettings& settings, std::uint64_t topologyVersion, Workers& workers) {
  prepare(cloths, topologyVersion);
  gather(cloths, &before);
  findPairs(settings.distance, 1.0, workers);
  measurePairs(settings.distance, workers);
  failSafe(settings.distance, workers);
  scatter(cloths);
  distance_ = -1.0;  // the pairs were for this move: the next substep finds its own
}

void SelfContact::solve(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings,
                        std::uint64_t topologyVersion, int substepsLeft, Workers& workers, PartClock* clock) {
  PartClock untimed;
  PartClock& parts = clock ? *clock : untimed;
  parts.time(Stage::broadPhase, [&] { findPairsIfNeeded(cloths, settings, topologyVersion, substepsLeft, workers); });
  parts.time(Stage::narrowPhase, [&] {
    measurePairs(settings.distance, workers);
    stats_.pairs = static_cast<std::int64_t>(pairs_.size());
  });
  parts.time(Stage::contactSweep, [&] {
    sweep(settings.distance, settings.friction, cloths);
    scatter(cloths);
  });
}

void SelfContact::findPairsIfNeeded(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings,
                                    std::uint64_t topologyVersion, int substepsLeft, Workers& workers) {
  const bool fresh = prepare(cloths, topologyVersion);
  gather(cloths, nullptr);
  // The pairs found at a substep serve on while every particle, at x0 and now, keeps half a
  // `distance` inside its box: two primitives within `distance` of each other are then still among
  // them. Where few particles did not (fewer than one in kStraysForSearch), only theirs are paired
  // again (a refresh, as the fail-safe does), else all are found anew. (The others' boxes, left
  // from earlier and larger motion, then pair them with more than a search would: the crumple at
  // 64 x 64 holds a fifth more bytes a particle; but its frames take 2 to 10 % less time, the
  // fold's a fifth less and the tear's a third: docs/self-contact.md.)
  bool together = false;  // most particles left their boxes at once
  if (!fresh && distance_ == settings.distance) {
    const bool few = strays(nullptr, 0.5 * settings.distance).size() * kStraysForSearch <= x_.size();
    together = 2 * strays_.size() >= x_.size();
    if (!strays_.empty() && few) refresh(strays_, workers);
    if (few) {
      reused_ = true;
      served_ = std::min(served_ + 1, kMostServed);  // (counted no further than it is compared)
      return;
    }
  }
  // Looking ahead pays while the motion is smooth enough for the pairs to serve again; where they
  // did not, the next boxes hold this substep's motion only. Where the last pairs served every
  // substep their boxes looked over and most particles then left their boxes at once (a cloth
  // carried along: rising-sphere's on its ball, a falling one), the next boxes look twice as far,
  // past the step, up to kMostAhead substeps: such a cloth otherwise searched once a step
  // (rising-sphere's self-contact 16 % less CPU time, drape-sphere's 5 %; a crumple's pile, whose
  // particles stray a few at a time, searches as before: docs/design.md).
  Real ahead = 1.0;
  if (reused_) {
    ahead = static_cast<Real>(std::max(substepsLeft, 1));
    if (together && served_ >= ahead_) ahead = std::max(ahead, std::min(2.0 * ahead_, kMostAhead));
  }
  findPairs(settings.distance, ahead, workers);
  distance_ = settings.distance;
  reused_ = false;
}

void SelfContact::pushAgain(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings) {
  std::size_t k = 0;
  for (const ClothRecord& record : cloths) {
    for (const Vec3& x : record.cloth.state.position) x_[k++] = x;
  }
  sweep(settings.distance, 0.0, cloths);
  scatter(cloths);
}

void SelfContact::finish(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings, Workers& workers,
                         PartClock* clock) {
  PartClock untimed;
  (clock ? *clock : untimed).time(Stage::failSafe, [&] {
    std::size_t k = 0;
    for (const ClothRecord& record : cloths) {
      for (const Vec3& x : record.cloth.state.position) x_[k++] = x;
    }
    failSafe(settings.distance, workers);
    scatter(cloths);
  });
}

}  // namespace drape::sim::contact
