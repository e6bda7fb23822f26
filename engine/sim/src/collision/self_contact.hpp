// Self-contact between triangles: cloth that never passes through itself.
//
// Once a substep, after the constraint sweeps, over every cloth of the world at once:
//
// 1. Broad phase. Each particle's motion over the substep (from x0, where the substep started, to
//    x, where the sweeps left it) is boxed, the box grown by `distance`; a triangle's and an edge's
//    box holds its corners' boxes. A tree of boxes over the mesh (fitted again each search, built
//    with the mesh) pairs every particle with the triangles and every edge with the edges whose
//    boxes its own overlaps (not those it is a corner or end of), but not a pair whose boxes lie
//    apart along the line between the two primitives' centres.
// 2. Contacts. For each pair, the closest points at x0 (barycentric on the triangle, or along the
//    two edges) and the direction between them, n. The contact keeps the two points at least the
//    target apart along n: `distance`, or less for parts of one cloth closer than that at rest (a
//    closed seam, its two sides on the same points, parts along the line between its sides'
//    triangles, by kSeamApart). It is linear in the positions, C(x) = sum_k c_k (n . x_k) - target
//    >= 0 with sum_k c_k = 0, and
//    projected a few sweeps, mass-weighted: linear momentum is kept exactly (to rounding), except
//    where that would move a particle far more than the points part (kContactLeverage, contacts.hpp). A pair whose
//    corners lie more than `distance` apart along the line between its centres, or else along the
//    line between its closest points at x0, all through the substep is far: not pushed (the
//    fail-safe proves it apart by those lines). What was proven of a pair (how far apart, along a
//    line) it keeps from one substep to the next, less how far its corners have gone since: a pair
//    still proven far is not looked at again. Then
//    Coulomb friction in position form on each pair that was pushed: the tangential part of its
//    relative motion, removed up to `friction` times the push, a push of at most `distance` (a
//    bigger one is a link pulled through the other layer being taken back, not layers pressed).
// 3. Fail-safe. Along the straight path from x0 to x, two primitives at x0-distance g can only
//    meet if their corners' relative motion m (the largest |dx_i - dx_j| between a corner of one
//    and of the other) reaches g. A pair with m < g is proven apart, as is one whose corners' hulls
//    over the substep lie apart along the line between its centres, or that its proof from the
//    contacts' measure still keeps apart. The pairs are looked at in parallel, each thread's run
//    in its own lists, joined in order. For the others, the triangles
//    around them are tested exactly (intersections.hpp's test, on the 2^-24 m grid) at x and at x0,
//    each pair of triangles once a round; where two of them intersect at x and did not at x0, their
//    free corners join an impact zone, which moves rigidly from x0 by its mass-weighted mean motion
//    (as it was at x0, so intersection-free, and with its momentum). Held and pinned corners join
//    only where a zone of free ones still passes through them (then they count as infinitely heavy
//    and the grip slips for the substep). Then again, testing the pairs whose triangles moved, until
//    none passes; before the rounds end, every pair that passed in any round is tested once more.
//    A pair still through with its corners in one zone already (a translation the exact grid's
//    rounding does not let it survive) stops that zone at x0 for the substep, and what passes
//    through a zone that stays joins it and stays too. Each round joins or stops something, so it
//    ends; where nothing is left to join or stop, the whole substep goes back to x0. Where the
//    contacts or a zone's move take particles out of their boxes, the pairs are found again first:
//    where fewer than one in eight left, those of the triangles and edges they are corners of only,
//    each by its box (a refresh: what a search would find), else by a search. A substep begins the
//    same way, where particles came within half a `distance` of their boxes' sides.
//
// A uniform motion is no contact at all (the relative motion is zero), so a falling cloth falls as
// it would without self-contact. Deterministic whatever the number of threads: the tree's walk lists
// the overlapping leaves in one order, their pairs are listed in parallel, in blocks of leaves that
// go to whichever thread is free, each block's in its own lists, joined in the blocks' order, and
// solved in it; the pairs' contacts are made in each thread's run of them, joined in that order.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "cloth_work.hpp"
#include "collision/exact_triangles.hpp"
#include "drape/sim/settings.hpp"
#include "drape/sim/world.hpp"
#include "parallel/workers.hpp"
#include "part_clock.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::contact {

class SelfContact {
 public:
  // A substep's self-contact comes in two calls, and the world applies the colliders' friction
  // between them (contact::friction), so that it answers to the weight the layers above put on a
  // layer, and the fail-safe still has the last word. Each cloth's solver scratch (in its record)
  // holds its collider contacts of this substep; the sweeps keep them too (a layer pushed down is not pushed through
  // the table), and what they push out counts into the contact's depth, as the constraint sweeps' does. `substepsLeft`:
  // in the step, this one included (the pairs found serve them all while they can). `parts` times the broad and the
  // narrow phase, the sweeps and the fail-safe.
  void solve(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings, std::uint64_t topologyVersion,
             int substepsLeft, Workers& workers, PartClock* parts = nullptr);
  void finish(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings, Workers& workers,
              PartClock* parts = nullptr);
  // Between the two: after World's sweep of the cloths solve's contacts pushed (with those held,
  // position::sweepAfterContacts), the same contacts pushed again from where it left the particles.
  // Without friction: that answered to the first pushes. Before, the pushes were the substep's last
  // word but for the fail-safe, and the links they drew out stayed long: the free links of the
  // bench's desk cases at 64 x 64 end (median of eight runs) crumple 23.8 -> 19.2 %, fold 1.9 ->
  // 0.9 %, tear 11.6 -> 8.9 % long; with the sweep alone the tear's were 17.1 % (docs/design.md).
  void pushAgain(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings);
  // Keeps a move made outside the substeps (a tear's relaxation, a cut putting particles on its
  // line) from passing cloth through cloth: the fail-safe alone, from `before` (per cloth, where each
  // particle was) to where the particles are, as if a substep had moved them so.
  void settle(std::vector<ClothRecord>& cloths, const std::vector<std::vector<Vec3>>& before,
              const SelfCollisionSettings& settings, std::uint64_t topologyVersion, Workers& workers);
  const SelfContactStats& stats() const { return stats_; }
  std::size_t bytes() const;

  // What the broad phase lists: 20 bytes, as many as a hundred a particle in a crumpled pile.
  struct Pair {
    std::uint32_t first, second;  // vertex and triangle, or the two edges (the lower first)
    // Its contact (an index into contacts_), or kFar: apart by more than the distance as the solve
    // began, so not measured and not pushed.
    std::uint32_t contact;
    // How far apart its two primitives were proven to be, m, along a line (the one between their
    // centres when it was last looked along), while each corner stays on its path as the pairs
    // were last measured (from x0Measured_ to xMeasured_); as they move off it, the proof holds
    // less by as far as each side's corners went (SelfContact::proven). -inf: nothing proven (a new
    // pair).
    float apart;
    bool edges;
    // Whether its two primitives lie at least the distance apart at rest (then they keep the
    // distance; else as far as at rest): kRestUnknown until first measured.
    std::uint8_t rest;
  };
  static constexpr std::uint8_t kRestUnknown = 0, kRestApart = 1, kRestNear = 2;
  static constexpr std::uint32_t kFar = 0xffffffffu;
  // A pair measured at x0 (those not far): what the sweeps push along.
  struct Contact {
    Real c[4];           // the contact point's weights: (1, -b0, -b1, -b2) or (1 - s, s, -(1 - t), -t)
    Vec3 normal;         // at x0, from the second point to the first
    Real gap0;           // distance at x0, m
    Real target;         // m
    Real push;           // correction along the normal this substep, m (for friction)
    std::uint32_t v[4];  // the pair's
    bool edges;
  };
  // The pairs last found (by a substep's search, its fail-safe's, or settle's), in the order they
  // are solved (for tests).
  const std::vector<Pair>& pairs() const { return pairs_; }
  // A pair's four particles: vertex-triangle, the vertex and the triangle's corners; edge-edge, the
  // first edge's ends and the second's.
  std::array<std::uint32_t, 4> corners(const Pair& pair) const {
    if (pair.edges) {
      const glm::uvec2 a = edges_[pair.first], b = edges_[pair.second];
      return {a[0], a[1], b[0], b[1]};
    }
    const glm::uvec3 t = triangles_[pair.second];
    return {pair.first, t[0], t[1], t[2]};
  }

 private:
  // Makes the mesh again if the topology changed; true if it did.
  bool prepare(const std::vector<ClothRecord>& cloths, std::uint64_t topologyVersion);
  // The broad phase: the pairs that may come within reach, found again where the last ones no
  // longer serve.
  void findPairsIfNeeded(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings,
                         std::uint64_t topologyVersion, int substepsLeft, Workers& workers);
  void buildMesh(const std::vector<ClothRecord>& cloths);
  void buildTree();
  void fitTree();
  // Positions and inverse masses into the world's numbering; x0 from `before` if given (settle),
  // else each particle's previous position, and then the collider contacts from the cloths' scratch.
  void gather(const std::vector<ClothRecord>& cloths, const std::vector<std::vector<Vec3>>* before);
  void scatter(std::vector<ClothRecord>& cloths) const;
  void findPairs(Real distance, Real ahead, Workers& workers);
  void measurePairs(Real distance, Workers& workers);
  Contact measure(Pair& pair, Real distance) const;
  // How far apart the pair's two sides lie along the line between its centres at x0, all along
  // the straight paths from x0 to x (the hull of each side's corners at both ends), m, less room
  // for rounding; -inf where they overlap there or a figure is not finite.
  Real separation(const Pair& pair) const;
  bool apartAlongCentres(const Pair& pair, Real margin) const { return separation(pair) > margin; }
  // The same along a given line (not of unit length): the line between the closest points at x0
  // (a contact's normal) proves apart what lies side by side, where the centres' line does not.
  Real separationAlong(const std::array<std::uint32_t, 4>& corners, int split, const Vec3& axis) const;
  // How far apart the pair is proven to be still, from what was proven when the pairs were last
  // measured and how far its corners went since (reach_, through primitiveReach_).
  Real proven(const Pair& pair) const;
  // primitiveReach_ from reach_: each triangle's and edge's farthest-gone corner.
  void reachOfPrimitives(Workers& workers);
  // reach_ of particle i: how far it now lies (x0 too, or x alone) from its path as it was
  // measured, the segment from x0Measured_ to xMeasured_. A proof holds for every position on that
  // path (it was made of the hull of both ends, or carried onto it), so a particle that goes back
  // and forth along it (pushed out by the contacts' sweep and drawn back in by the constraints,
  // substep after substep, in a pile at rest) takes nothing from its pairs' proofs.
  void reachOf(std::uint32_t i, bool fromX0) {
    const Vec3 a = x0Measured_[i], along = xMeasured_[i] - a;
    const Real length2 = glm::dot(along, along);
    const auto from = [&](const Vec3& x) {
      const Real t = length2 > 0.0 ? std::clamp(glm::dot(x - a, along) / length2, 0.0, 1.0) : 0.0;
      const Vec3 d = x - (a + along * t);
      return glm::dot(d, d);
    };
    Real r = from(x_[i]);
    if (fromX0) r = std::max(r, from(x0_[i]));
    reach_[i] = std::sqrt(r);
  }
  void sweep(Real distance, Real friction, std::vector<ClothRecord>& cloths);
  void failSafe(Real distance, Workers& workers);
  // In the fail-safe's later rounds: primitiveMoved_ from movedTriangles_.
  void primitivesMoved();
  // Of `candidates` (every particle where null), those not `margin` inside their boxes at x0 and
  // now (in strays_).
  const std::vector<std::uint32_t>& strays(const std::vector<std::uint32_t>* candidates, Real margin);
  // In the fail-safe: the pairs kept whole for the motion as it now is, where any of `candidates`
  // left its box: by a refresh of the few that did (their primitives paired again by their boxes,
  // the particles' boxes now their motion), or a search where many did; whether either was needed.
  bool keepPairs(const std::vector<std::uint32_t>* candidates, Real distance, Workers& workers);
  void refresh(const std::vector<std::uint32_t>& strays, Workers& workers);
  // A triangle's or edge's box from its corners' (k: its index among the boxes), or none where it
  // is torn; whether it is; whether two primitives' boxes lie apart along the line between their centres (findPairs).
  void boxPrimitive(std::size_t k);
  bool torn(const std::uint32_t* corners, int count) const;
  bool apartBoxes(const std::uint32_t* corners, int split) const;
  // Whose boxes overlap, listed as a search and a refresh list them (far, unproven, new): vertex v
  // and triangle t unless v is a corner of t; edges e and f unless they share an end; either unless
  // apartBoxes proves them apart.
  void listVertexTriangle(std::uint32_t v, std::uint32_t t, std::vector<Pair>& out) const;
  void listEdgeEdge(std::uint32_t e, std::uint32_t f, std::vector<Pair>& out) const;

  std::uint64_t meshVersion_ = 0;
  std::size_t meshParticles_ = 0;
  // The world's mesh, particles numbered across cloths.
  std::vector<std::uint32_t> clothOf_;                        // per particle
  std::vector<std::uint32_t> clothStart_;                     // per cloth: its first particle
  std::vector<Vec3> rest_;                                    // rest positions
  std::vector<Real> clothSize_;                               // per cloth: its rest box's diagonal, squared
  std::vector<glm::uvec3> triangles_;                         // world-wide corners
  std::vector<glm::uvec2> edges_;                             // unique, lower particle first
  std::vector<std::uint32_t> edgeTriangles_;                  // two per edge (kNone where only one)
  std::vector<std::uint32_t> vertexStart_, vertexTriangles_;  // the triangles around each particle

  // This substep.
  std::vector<Vec3> x0_, x_;  // where each particle was when the substep began, and is now
  Real distance_ = 0.0;       // the pairs were found for
  bool reused_ = true;        // the pairs last found served a second substep
  Real ahead_ = 1.0;          // how many substeps of motion the last search's boxes held
  int served_ = 0;            // substeps the pairs last found have served, that one included
  static constexpr Real kMostAhead = 8.0;
  static constexpr int kMostServed = 1000;
  std::vector<Real> w_;  // inverse masses
  struct Plane {
    std::uint32_t particle;
    std::uint32_t cloth, index;  // of the particle in its cloth
    Vec3 normal;
    Real offset;  // the particle keeps normal . x >= offset
  };
  std::vector<Plane> planes_;                   // the collider contacts of this substep
  std::vector<Vec3> lower_, upper_;             // boxes of the particles, triangles, edges: in that order
  std::vector<glm::vec3> boxLower_, boxUpper_;  // the same in single precision, rounded outwards
  Real grow_ = 0.0;                             // how far the boxes reach beyond the motion, m
  // A refresh's primitives (particles, triangles, edges, flagged), the particles that left their
  // boxes, and the tree's walk.
  std::vector<std::uint8_t> affected_;
  std::vector<std::uint32_t> strays_, walk_;
  std::vector<std::uint32_t> refreshed_;  // a refresh's primitives, in their order (refresh)
  // The broad phase's tree (a bounding-volume hierarchy), built with the mesh from the rest shape:
  // cloth by cloth, then halving the triangles at the median along the longest side of their rest
  // centroids, down to leaves of at most kLeafTriangles items (triangles, and particles in no
  // triangle). Every primitive belongs to one leaf: a
  // triangle to its own, a vertex and an edge to the leaf of their first triangle (a particle in
  // no triangle, as a chain's, to a leaf of its own). A search fits each leaf's box around what it
  // holds and each node's around its children, then walks the tree against itself for the pairs
  // of leaves whose boxes overlap, and tests their primitives: each pair of primitives whose boxes
  // overlap is then found exactly once, in the pair of leaves that hold them.
  struct Node {
    glm::vec3 lower, upper;
    std::uint32_t left, right;  // children; a leaf: right is kNone and left its leaf
  };
  std::vector<Node> nodes_;                                       // parents before children
  std::vector<std::uint32_t> leafTriangleStart_, leafTriangles_;  // per leaf, its triangles
  std::vector<std::uint32_t> leafVertexStart_, leafVertices_;     // ... its vertices
  std::vector<std::uint32_t> leafEdgeStart_, leafEdges_;          // ... its edges
  std::vector<std::uint32_t> leafNode_;                           // per leaf, its node
  std::vector<std::uint32_t> primitiveLeaf_;        // per particle, triangle and edge (as the boxes): its leaf
  std::vector<std::uint64_t> leafPairs_;            // this search's overlapping leaves (lower in the high word)
  std::vector<std::vector<std::uint64_t>> walked_;  // per part of the walk: its overlapping leaves
  std::vector<std::int64_t> walkTests_;             // per thread: node boxes compared in the walk
  std::vector<std::vector<Pair>> found_;  // per block of leaf pairs: vertex-triangle pairs, then edge-edge pairs
  std::vector<std::int64_t> boxTests_;    // per thread: primitive boxes compared
  std::vector<Pair> pairs_;
  std::vector<Contact> contacts_;             // the pairs not far, in the pairs' order (then the fail-safe's)
  std::vector<std::size_t> runNear_;          // measurePairs: where each run's contacts begin
  std::vector<std::uint32_t> active_;         // contacts the sweeps look at
  std::vector<Vec3> x0Measured_, xMeasured_;  // x0 and x as the pairs were last measured
  // Per particle: how far it has gone from the segment between them (now, and at x0 too where the
  // measure asks).
  std::vector<Real> reach_;
  // Per triangle, then per edge: the largest reach_ of its corners (what proven() takes of a side),
  // so that a pair's proof reads two numbers, not its four corners'.
  std::vector<Real> primitiveReach_;
  // The largest coordinate of any particle at x0 or now, as measurePairs began (the rounding room of
  // separation grows with it).
  Real coordinates_ = 0.0;
  // The fail-safe's impact zones, per particle: its parent in the zones' union-find, whether it is
  // in a zone, and (per zone root) whether a held or pinned particle is in it; per triangle, whether
  // the last round moved a corner; whether a zone stays at x0 for the substep (its move as one body
  // did not clear a pair through it), per member and per zone root in a round; the round's zones of
  // such pairs; and the substep's pairs through, every round's.
  std::vector<std::uint32_t> zone_;
  std::vector<std::uint8_t> inZone_, heavy_, triangleMoved_, stays_, staysRoot_;
  std::vector<std::uint32_t> movedTriangles_;  // in a fail-safe round: those triangleMoved_ marks
  // Per vertex, then per edge: 0 without triangles, 1 with, 3 where one of them moved this round.
  std::vector<std::uint8_t> primitiveMoved_;
  std::vector<std::uint32_t> stuck_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> everPassing_;
  // Its exact tests: the pairs of triangles of a round (lower index in the high word) and whether
  // each intersects now; the exact triangles made at x0 and at x (slot per triangle, kNone if not
  // made, and the triangles made).
  std::vector<std::uint64_t> tests_;
  // Per thread, as the pairs are looked at: the tests found, the far pairs measured (by index), and
  // how many pairs were tested.
  std::vector<std::vector<std::uint64_t>> scanTests_;
  std::vector<std::vector<std::pair<std::uint32_t, Contact>>> scanContacts_;
  std::vector<std::int64_t> scanTested_;
  std::vector<std::uint8_t> hits_;
  std::vector<std::uint32_t> slot0_, slotX_, which0_, whichX_;
  std::vector<std::optional<exact::Triangle>> made0_, madeX_;
  SelfContactStats stats_;
};

}  // namespace drape::sim::contact
