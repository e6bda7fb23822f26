#include "topology/topology.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <tuple>

#include <glm/geometric.hpp>

#include "solver/pair_order.hpp"

namespace drape::sim::topology {

namespace {

using Triangle = glm::uvec3;

int cornerOf(const Triangle& t, ParticleIndex v) {
  for (int k = 0; k < 3; ++k) {
    if (t[k] == v) return k;
  }
  return -1;
}

// Particle -> triangles using it, in compressed rows.
struct Incidence {
  std::vector<std::uint32_t> start, list;

  Incidence(const std::vector<Triangle>& triangles, std::size_t particles) : start(particles + 1, 0) {
    for (const Triangle& t : triangles) {
      for (int k = 0; k < 3; ++k) ++start[t[k] + 1];
    }
    std::partial_sum(start.begin(), start.end(), start.begin());
    list.resize(start.back());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::uint32_t i = 0; i < triangles.size(); ++i) {
      for (int k = 0; k < 3; ++k) list[fill[triangles[i][k]]++] = i;
    }
  }
  const std::uint32_t* begin(ParticleIndex v) const { return list.data() + start[v]; }
  const std::uint32_t* end(ParticleIndex v) const { return list.data() + start[v + 1]; }
};

// The recipes that make constraint c from the triangles. With allowFree, a pair no triangle
// witnesses gets a free link; without, none.
void addTemplates(Topology& topology, const ClothRest& rest, const Incidence& incidence, ConstraintKind kind,
                  const DistanceConstraint& c, bool allowFree = true) {
  const auto& triangles = rest.triangles;
  const std::size_t first = topology.templates.size();
  ConstraintTemplate base;
  base.kind = kind;
  base.restLength = c.restLength;
  // Edges of a triangle.
  for (auto t = incidence.begin(c.a); t != incidence.end(c.a); ++t) {
    const int cb = cornerOf(triangles[*t], c.b);
    if (cb < 0) continue;
    ConstraintTemplate x = base;
    x.link = ConstraintTemplate::Link::same;
    x.t1 = x.t2 = *t;
    x.corner1 = static_cast<std::uint8_t>(cornerOf(triangles[*t], c.a));
    x.corner2 = static_cast<std::uint8_t>(cb);
    topology.templates.push_back(x);
  }
  if (topology.templates.size() > first) return;
  // The other diagonal of a quad: a and b in two triangles joined across an edge.
  for (auto t = incidence.begin(c.a); t != incidence.end(c.a); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t other = topology.neighbour[*t][static_cast<std::size_t>(k)];
      if (other < 0) continue;
      const int cb = cornerOf(triangles[static_cast<std::size_t>(other)], c.b);
      if (cb < 0) continue;
      ConstraintTemplate x = base;
      x.link = ConstraintTemplate::Link::across;
      x.t1 = *t;
      x.t2 = static_cast<std::uint32_t>(other);
      x.corner1 = static_cast<std::uint8_t>(cornerOf(triangles[*t], c.a));
      x.corner2 = static_cast<std::uint8_t>(cb);
      x.middle1 = static_cast<std::uint8_t>(k);
      topology.templates.push_back(x);
    }
  }
  if (topology.templates.size() > first) return;
  // A bend: a and b both next to a middle particle m.
  for (auto t = incidence.begin(c.a); t != incidence.end(c.a); ++t) {
    const Triangle& t1 = triangles[*t];
    for (int m = 0; m < 3; ++m) {
      if (t1[m] == c.a) continue;
      for (auto u = incidence.begin(t1[m]); u != incidence.end(t1[m]); ++u) {
        const int cb = cornerOf(triangles[*u], c.b);
        if (cb < 0) continue;
        ConstraintTemplate x = base;
        x.link = ConstraintTemplate::Link::through;
        x.t1 = *t;
        x.t2 = *u;
        x.corner1 = static_cast<std::uint8_t>(cornerOf(t1, c.a));
        x.corner2 = static_cast<std::uint8_t>(cb);
        x.middle1 = static_cast<std::uint8_t>(m);
        x.middle2 = static_cast<std::uint8_t>(cornerOf(triangles[*u], t1[m]));
        topology.templates.push_back(x);
      }
    }
  }
  if (topology.templates.size() > first || !allowFree) return;
  ConstraintTemplate x = base;
  x.link = ConstraintTemplate::Link::free;
  x.t1 = c.a;
  x.t2 = c.b;
  topology.templates.push_back(x);
}

// Rebuilds every constraint list from the templates and the current triangles.
void rebuildConstraints(Cloth& cloth) {
  Topology& topology = cloth.topology;
  const auto& triangles = cloth.rest.triangles;
  struct Made {
    ConstraintKind kind;
    ParticleIndex a, b;
    std::uint32_t from;
  };
  std::vector<Made> made;
  made.reserve(topology.templates.size());
  for (std::uint32_t i = 0; i < topology.templates.size(); ++i) {
    const ConstraintTemplate& x = topology.templates[i];
    ParticleIndex a = 0, b = 0;
    switch (x.link) {
      case ConstraintTemplate::Link::same:
        a = triangles[x.t1][x.corner1];
        b = triangles[x.t1][x.corner2];
        break;
      case ConstraintTemplate::Link::across:
        if (topology.neighbour[x.t1][x.middle1] != static_cast<std::int32_t>(x.t2)) continue;
        a = triangles[x.t1][x.corner1];
        b = triangles[x.t2][x.corner2];
        break;
      case ConstraintTemplate::Link::through:
        if (triangles[x.t1][x.middle1] != triangles[x.t2][x.middle2]) continue;
        a = triangles[x.t1][x.corner1];
        b = triangles[x.t2][x.corner2];
        break;
      case ConstraintTemplate::Link::free:
        if (x.broken) continue;
        a = x.t1;
        b = x.t2;
        break;
    }
    if (a == b) continue;
    made.push_back({x.kind, std::min(a, b), std::max(a, b), i});
  }
  // In order of kind, a, b and template (the templates come in order): counted out by kind and a
  // (which keeps the templates' order), then each particle's few by b. A rebuild follows every
  // breaking pass; sorting the whole list by comparison took 40 % of the desk tear's tearing time
  // at 64 x 64, a quarter at 128 x 128.
  {
    const std::size_t particles = cloth.rest.particleCount();
    const auto bucket = [&](const Made& m) { return static_cast<std::size_t>(m.kind) * particles + m.a; };
    std::vector<std::uint32_t> start(kConstraintKindCount * particles + 1, 0);
    for (const Made& m : made) ++start[bucket(m) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<Made> sorted(made.size());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (const Made& m : made) sorted[fill[bucket(m)]++] = m;
    for (std::size_t k = 0; k + 1 < start.size(); ++k) {
      for (std::size_t i = start[k] + 1; i < start[k + 1]; ++i) {  // insertion: stable, and a fan is short
        const Made m = sorted[i];
        std::size_t j = i;
        for (; j > start[k] && m.b < sorted[j - 1].b; --j) sorted[j] = sorted[j - 1];
        sorted[j] = m;
      }
    }
    made.swap(sorted);
  }
  made.erase(std::unique(made.begin(), made.end(),
                         [](const Made& l, const Made& r) { return l.kind == r.kind && l.a == r.a && l.b == r.b; }),
             made.end());
  for (std::size_t k = 0; k < kConstraintKindCount; ++k) {
    cloth.rest.constraints[k].clear();
    topology.source[k].clear();
  }
  for (const Made& m : made) {
    const auto k = static_cast<std::size_t>(m.kind);
    cloth.rest.constraints[k].push_back({m.a, m.b, topology.templates[m.from].restLength});
    topology.source[k].push_back(m.from);
  }
}

void sever(Topology& topology, std::uint32_t t, int edge) {
  const std::int32_t other = topology.neighbour[t][static_cast<std::size_t>(edge)];
  if (other < 0) return;
  topology.neighbour[t][static_cast<std::size_t>(edge)] = -1;
  ++topology.torn;
  for (std::int32_t& back : topology.neighbour[static_cast<std::size_t>(other)]) {
    if (back == static_cast<std::int32_t>(t)) back = -1;
  }
}

// About `wanted` kilograms taken from `left` (wanted > 0): the share, with what is left in `left`,
// the two adding up to what `left` was exactly. Where the share is at least half of left, left -
// share is exact (Sterbenz); else left - share rounded is at least half of left, and left minus
// that is exact. Neither part is less than 1/64 of
// what left was: a share of a degenerate triangle's area (nothing, or so little that left minus it
// rounds back to left) would leave a particle with no mass, its inverse infinite, and the next
// correction would make it NaN (a fuzzed snapshot with a particle's rest position moved 1 m
// off). So a particle's mass stays a normal float: only some 20 splits in a row, each
// leaving the least, would take 0.03 kg below 1e-38.
MassReal takeShare(MassReal& left, Real wanted) {
  const Real least = static_cast<Real>(left) / 64.0;
  MassReal share = static_cast<MassReal>(std::clamp(wanted, least, static_cast<Real>(left) - least));
  if (!(share < left)) share = 0.5f * left;
  if (share >= 0.5f * left) {
    left -= share;
    return share;
  }
  const MassReal rest = left - share;
  share = left - rest;
  left = rest;
  return share;
}

// Gives every fan of triangles around each touched particle but the first a particle of its own.
void splitParticles(Cloth& cloth, std::vector<ParticleIndex> touched, std::size_t budget,
                    std::vector<ParticleSplit>& splits) {
  ClothRest& rest = cloth.rest;
  ParticleState& s = cloth.state;
  const Topology& topology = cloth.topology;
  const Incidence incidence(rest.triangles, rest.particleCount());
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  std::vector<std::uint32_t> fan;
  std::vector<int> group;
  std::vector<Real> area;
  for (const ParticleIndex v : touched) {
    fan.assign(incidence.begin(v), incidence.end(v));
    group.assign(fan.size(), -1);
    int groups = 0;
    // Flood each fan through the edges at v that are still joined.
    for (std::size_t start = 0; start < fan.size(); ++start) {
      if (group[start] >= 0) continue;
      group[start] = groups;
      std::vector<std::size_t> stack{start};
      while (!stack.empty()) {
        const std::uint32_t t = fan[stack.back()];
        stack.pop_back();
        const int cv = cornerOf(rest.triangles[t], v);
        for (const int edge : {cv, (cv + 2) % 3}) {  // the two edges of t that meet at v
          const std::int32_t other = topology.neighbour[t][static_cast<std::size_t>(edge)];
          if (other < 0) continue;
          const auto at = std::find(fan.begin(), fan.end(), static_cast<std::uint32_t>(other));
          if (at == fan.end()) continue;
          const auto j = static_cast<std::size_t>(at - fan.begin());
          if (group[j] < 0) {
            group[j] = groups;
            stack.push_back(j);
          }
        }
      }
      ++groups;
    }
    if (groups < 2) continue;
    area.assign(static_cast<std::size_t>(groups), 0.0);
    Real total = 0.0;
    for (std::size_t j = 0; j < fan.size(); ++j) {
      area[static_cast<std::size_t>(group[j])] += topology.triangleArea[fan[j]];
      total += topology.triangleArea[fan[j]];
    }
    // Shares by area, with a floor so that a fan of degenerate (zero-area) triangles still gets a
    // positive mass.
    Real weights = 0.0;
    for (Real& a : area) {
      a += total > 0.0 ? 1e-6 * total : 1.0;
      weights += a;
    }
    // Each copy's share is taken from what v has left, so that what v keeps and the share add up
    // to what it had exactly, in single precision (MassReal): tearing neither makes nor loses mass.
    MassReal left = s.mass[v];
    for (int g = 1; g < groups && budget > 0; ++g, --budget) {
      const auto copy = static_cast<ParticleIndex>(rest.particleCount());
      const MassReal share =
          takeShare(left, static_cast<Real>(s.mass[v]) * area[static_cast<std::size_t>(g)] / weights);
      rest.duplicateRestPosition(v);
      s.position.push_back(s.position[v]);
      s.previousPosition.push_back(s.previousPosition[v]);
      if (!s.velocity.empty()) s.velocity.push_back(s.velocity[v]);
      s.mass.push_back(share);
      s.inverseMass.push_back(s.inverseMass[v] > 0.0 ? 1.0 / share : 0.0);
      s.pinned.push_back(s.pinned[v]);
      for (std::size_t j = 0; j < fan.size(); ++j) {
        if (group[j] == g) rest.triangles[fan[j]][cornerOf(rest.triangles[fan[j]], v)] = copy;
      }
      splits.push_back({v, copy});
    }
    s.mass[v] = left;
    if (s.inverseMass[v] > 0.0) s.inverseMass[v] = 1.0 / s.mass[v];
  }
}

// A triangle's edge, by the particles at its ends (lower << 32 | higher).
struct EdgeUse {
  std::uint64_t key;
  std::uint32_t triangle;
  int edge;
};

// Joins each two triangles that use the same edge; an edge of three or more joins none of them.
void joinAlongEdges(Topology& topology, std::vector<EdgeUse>& uses) {
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& l, const EdgeUse& r) {
    return std::tie(l.key, l.triangle, l.edge) < std::tie(r.key, r.triangle, r.edge);
  });
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i == 2) {
      topology.neighbour[uses[i].triangle][static_cast<std::size_t>(uses[i].edge)] =
          static_cast<std::int32_t>(uses[i + 1].triangle);
      topology.neighbour[uses[i + 1].triangle][static_cast<std::size_t>(uses[i + 1].edge)] =
          static_cast<std::int32_t>(uses[i].triangle);
    }
    i = j;
  }
}

// Every constraint's recipes, from the constraints and triangles as they are now: as a world
// loaded from a snapshot of this one would make them, so the two run on alike.
void makeTemplates(Cloth& cloth) {
  Topology& topology = cloth.topology;
  const ClothRest& rest = cloth.rest;
  const Incidence incidence(rest.triangles, rest.particleCount());
  topology.templates.clear();
  for (ConstraintKind kind : kConstraintKinds) {
    auto& source = topology.source[static_cast<std::size_t>(kind)];
    source.clear();
    for (const DistanceConstraint& c : rest.of(kind)) {
      source.push_back(static_cast<std::uint32_t>(topology.templates.size()));
      addTemplates(topology, rest, incidence, kind, c);
    }
  }
}

}  // namespace

Real madeSpacing(const Cloth& cloth) {
  const ClothSettings& settings = cloth.settings;
  if (settings.mesh && settings.mesh->spacing > 0.0) return settings.mesh->spacing;
  if (!settings.mesh) {
    const LatticeSpec& l = settings.lattice;
    Real spacing = std::numeric_limits<Real>::infinity();
    if (l.columns > 1) spacing = std::min(spacing, l.width / (l.columns - 1));
    if (l.rows > 1) spacing = std::min(spacing, l.height / (l.rows - 1));
    if (std::isfinite(spacing) && spacing > 0.0) return spacing;
  }
  std::vector<Real> lengths;
  for (const DistanceConstraint& c : cloth.rest.of(ConstraintKind::stretch)) lengths.push_back(c.restLength);
  if (lengths.empty()) return 0.0;
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2), lengths.end());
  return lengths[lengths.size() / 2];
}

void build(Cloth& cloth) {
  Topology& topology = cloth.topology;
  if (topology.built) return;
  const ClothRest& rest = cloth.rest;
  const auto& triangles = rest.triangles;
  topology.neighbour.assign(triangles.size(), {-1, -1, -1});
  topology.triangleArea.resize(triangles.size());
  // Pair up the triangles on each edge; an edge of three or more triangles joins none of them.
  std::vector<EdgeUse> uses;
  uses.reserve(triangles.size() * 3);
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    topology.triangleArea[t] = 0.5 * glm::length(glm::cross(rest.restPosition(tri[1]) - rest.restPosition(tri[0]),
                                                            rest.restPosition(tri[2]) - rest.restPosition(tri[0])));
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t lo = std::min(tri[k], tri[(k + 1) % 3]), hi = std::max(tri[k], tri[(k + 1) % 3]);
      uses.push_back({lo << 32 | hi, t, k});
    }
  }
  joinAlongEdges(topology, uses);
  makeTemplates(cloth);
  topology.built = true;
}

namespace {

// Cutting through triangles. A particle is on the cut's line when it lies within kOnLine spacings
// of the cut's plane; every other particle is on one side. An edge whose ends lie on opposite sides
// gets a new particle where the plane crosses it (so no piece of an edge is shorter than kOnLine
// spacings), and a particle on the line is moved along one of its edges onto the plane (by at most
// kOnLine spacings, and at most a quarter of its shortest edge, so none of its triangles folds over).
constexpr Real kOnLine = 0.3;
// Two crossings of one triangle closer than this many spacings share a particle (openAlong).
constexpr Real kMergeChord = 0.2;
// Tries at sharing before every crossing keeps its own particle.
constexpr int kMergeAttempts = 4;
// A child a shared particle makes needs at least this many spacings squared of doubled area.
constexpr Real kLeastMergedArea = 2e-2;
// Nor may the move leave one of its triangles with an angle under this (radians), smaller than it
// was: among the small triangles many crossing cuts leave, a particle moved onto the line could
// flatten a triangle whose other corners lie on it too (0.8 degrees after a tear there).
constexpr Real kSnapLeastAngle = 10.0 * 3.14159265358979323846 / 180.0;
// A triangle a particle moved onto the line leaves needs at least this many.
constexpr Real kLeastChildArea = 1e-3;

Real restEdge(const ClothRest& rest, ParticleIndex a, ParticleIndex b) {
  return glm::length(rest.restPosition(b) - rest.restPosition(a));
}

// The smallest angle of a triangle with these corners, in radians (0 for a degenerate one); and of
// a triangle of particles at rest.
Real smallestAngleOf(const Vec3 (&p)[3]) {
  Real least = 3.2;
  for (int k = 0; k < 3; ++k) {
    const Vec3 u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
    const Real lu = glm::length(u), lv = glm::length(v);
    if (!(lu > 0.0) || !(lv > 0.0)) return 0.0;
    least = std::min(least, std::acos(std::clamp(glm::dot(u, v) / (lu * lv), -1.0, 1.0)));
  }
  return least;
}
Real smallestAngle(const ClothRest& rest, ParticleIndex a, ParticleIndex b, ParticleIndex c) {
  const Vec3 p[3] = {rest.restPosition(a), rest.restPosition(b), rest.restPosition(c)};
  return smallestAngleOf(p);
}

// A new particle at a + s (b - a), at rest and now; its mass is set later (cutMasses).
ParticleIndex insertParticle(Cloth& cloth, ParticleIndex a, ParticleIndex b, Real s) {
  ClothRest& rest = cloth.rest;
  ParticleState& st = cloth.state;
  const auto p = static_cast<ParticleIndex>(rest.particleCount());
  const glm::vec3 offset = rest.restOffsets[a] + static_cast<float>(s) * (rest.restOffsets[b] - rest.restOffsets[a]);
  rest.restOffsets.push_back(offset);
  st.position.push_back(glm::mix(st.position[a], st.position[b], s));
  st.previousPosition.push_back(glm::mix(st.previousPosition[a], st.previousPosition[b], s));
  if (!st.velocity.empty()) st.velocity.push_back(glm::mix(st.velocity[a], st.velocity[b], s));
  const bool pinned = st.pinned[a] && st.pinned[b];
  st.mass.push_back(0.0f);
  st.inverseMass.push_back(pinned ? 0.0 : 1.0);
  st.pinned.push_back(pinned ? 1 : 0);
  return p;
}

// Takes the particles from `count` on away again (made by insertParticle, their masses not set yet).
void truncateParticles(Cloth& cloth, std::size_t count) {
  ClothRest& rest = cloth.rest;
  ParticleState& st = cloth.state;
  rest.restOffsets.resize(count);
  st.position.resize(count);
  st.previousPosition.resize(count);
  if (!st.velocity.empty()) st.velocity.resize(count);
  st.mass.resize(count);
  st.inverseMass.resize(count);
  st.pinned.resize(count);
}

// A triangle a cut splits: its corners and neighbours before, and what it became.
struct Split {
  std::uint32_t parent;
  Triangle corners;
  std::array<std::int32_t, 3> neighbour;
  struct Child {
    Triangle corners;
    std::array<std::int8_t, 3> from;  // per edge: the parent's edge it lies on, or -1 inside the parent
    std::uint32_t index = 0;
  };
  std::vector<Child> children;
  int cutEdgeChild = -1, cutEdge = -1;  // the child edge the cut runs along, if it runs through
};

// One opening of the mesh along a line: the plane it lies in (as each particle's signed distance
// from it, m) and which of the particles and edge crossings are part of it.
struct Line {
  std::vector<Real> distance;       // per particle
  std::vector<std::int8_t> side;    // per particle: -1, 1, or 0 within kOnLine spacings of the plane
  std::vector<std::uint8_t> onCut;  // per particle: on the line and part of the opening
  std::vector<std::uint8_t> joins;  // per particle: an opening reaching its triangle runs on to it (a swipe's tips)
  std::function<bool(ParticleIndex, ParticleIndex, Real)> counts;  // whether edge p-q's crossing at p + s (q - p) is
  Real onLine = 0.0;                                               // m: kOnLine spacings

  Line(std::size_t particles, Real spacing)
      : distance(particles), side(particles), onCut(particles, 0), joins(particles, 0), onLine(kOnLine * spacing) {}
  // Particle p lies `d` metres from the plane.
  void place(std::size_t p, Real d) {
    distance[p] = d;
    side[p] = std::abs(d) < onLine ? 0 : d > 0.0 ? 1 : -1;
  }
};

// What openings have done that the constraints and particles must follow (finishOpening).
struct Opening {
  std::vector<ParticleIndex> touched;  // ends of severed edges
  std::vector<ParticleIndex> moved;    // particles moved onto a line
  std::size_t firstNew = 0;            // the first particle the openings made
  bool changed = false;
};

// Splits the triangles the line crosses (those of `consider`, or all) and severs the mesh along it.
// New particles are appended to `inserted`.
void openAlong(Cloth& cloth, Line& line, const std::vector<std::uint32_t>* consider, std::size_t& particleBudget,
               std::vector<ParticleInsert>& inserted, Opening& opening) {
  Topology& topology = cloth.topology;
  ClothRest& rest = cloth.rest;
  ParticleState& s = cloth.state;
  const std::size_t n0 = rest.particleCount();
  const std::size_t t0 = rest.triangles.size();
  const std::size_t insertedBefore = inserted.size();
  std::vector<Real>& distance = line.distance;
  const std::vector<std::int8_t>& side = line.side;
  const auto onCut = [&](ParticleIndex p) { return p < n0 && line.onCut[p] != 0; };
  const auto key = [](ParticleIndex p, ParticleIndex q) {
    return static_cast<std::uint64_t>(std::min(p, q)) << 32 | std::max(p, q);
  };
  const auto crosses = [&](ParticleIndex p, ParticleIndex q) { return side[p] * side[q] < 0; };
  // The side of the plane a triangle's third corner lies on, beside an edge on the cut: its side,
  // or for a particle within kOnLine spacings, the sign of its distance. A thin triangle along the
  // line (as earlier cuts and a crack's flanks leave) has all three corners within them; taking
  // them all as on the line left its edge on the cut joined, and the cloth joined across the cut
  // (and a crack's tip held still there).
  const auto sideOf = [&](ParticleIndex p) -> int {
    if (side[p] != 0) return side[p];
    return distance[p] > 0.0 ? 1 : distance[p] < 0.0 ? -1 : 0;
  };
  const auto crossingAt = [&](ParticleIndex p, ParticleIndex q) { return distance[p] / (distance[p] - distance[q]); };
  // New particles where the plane crosses an edge, one per edge.
  std::vector<std::pair<std::uint64_t, ParticleIndex>> crossing;       // edge key -> its particle
  std::vector<std::pair<ParticleIndex, ParticleIndex>> borderCrossed;  // of `consider`: crossed border edges
  const auto look = [&](std::uint32_t t) {
    for (int k = 0; k < 3; ++k) {
      const ParticleIndex p = rest.triangles[t][k], q = rest.triangles[t][(k + 1) % 3];
      if (!crosses(p, q) || !line.counts(p, q, crossingAt(p, q))) continue;
      crossing.push_back({key(p, q), 0});
      if (consider && topology.neighbour[t][static_cast<std::size_t>(k)] < 0) borderCrossed.push_back({p, q});
    }
  };
  if (consider) {
    for (const std::uint32_t t : *consider) look(t);
  } else {
    for (std::uint32_t t = 0; t < t0; ++t) look(t);
  }
  const Incidence incidence(rest.triangles, n0);
  // An opening of some triangles only (a crack's break) that ends on a border edge where a seam
  // is still closed (an earlier opening's two flanks: copies of the same particles, at the same
  // point at rest, on each other) splits the other flank's edge at the same point too. Else a
  // corner of this flank lies on the other flank's edge, a T-junction where the two touch, and
  // the flanks no longer have matching corners to close on. (An opening of every triangle, a cut,
  // crosses both edges anyway.)
  for (const auto& [p, q] : borderCrossed) {
    for (std::size_t a = 0; a < n0; ++a) {
      if (a == p || rest.restOffsets[a] != rest.restOffsets[p]) continue;
      const auto twin = static_cast<ParticleIndex>(a);
      for (auto t = incidence.begin(twin); t != incidence.end(twin); ++t) {
        const Triangle& c = rest.triangles[*t];
        for (int k = 0; k < 3; ++k) {
          const ParticleIndex u = c[k], w = c[(k + 1) % 3];
          if (topology.neighbour[*t][static_cast<std::size_t>(k)] >= 0 || (u != twin && w != twin)) continue;
          const ParticleIndex other = u == twin ? w : u;
          if (rest.restOffsets[other] != rest.restOffsets[q]) continue;  // q itself where the seam ends there
          if (crosses(u, w) && line.counts(u, w, crossingAt(u, w))) crossing.push_back({key(u, w), 0});
        }
      }
    }
  }
  std::sort(crossing.begin(), crossing.end());
  crossing.erase(std::unique(crossing.begin(), crossing.end()), crossing.end());
  if (crossing.size() > particleBudget) return;
  // Particles on the line go onto the plane, along the edge that takes them there soonest.
  for (std::size_t p = 0; p < n0; ++p) {
    if (side[p] != 0 || distance[p] == 0.0 || s.inverseMass[p] == 0.0) continue;
    if (!line.onCut[p]) continue;
    Real best = std::numeric_limits<Real>::infinity(), shortest = best, bestS = 0.0;
    ParticleIndex to = 0;
    for (auto t = incidence.begin(static_cast<ParticleIndex>(p)); t != incidence.end(static_cast<ParticleIndex>(p));
         ++t) {
      for (int k = 0; k < 3; ++k) {
        const ParticleIndex q = rest.triangles[*t][k];
        if (q == p) continue;
        const Real edge = restEdge(rest, static_cast<ParticleIndex>(p), q);
        shortest = std::min(shortest, edge);
        if (side[q] == 0 || !std::isfinite(distance[q]) || (distance[q] > 0.0) == (distance[p] > 0.0)) continue;
        const Real at = distance[p] / (distance[p] - distance[q]);
        if (at * edge < best) {
          best = at * edge;
          bestS = at;
          to = q;
        }
      }
    }
    if (!(best <= 0.4 * shortest)) continue;
    // Several breaks of one tear can each move a particle by that much, together turning a
    // triangle over: none of its triangles may come to face the other way, or lie flat, at rest
    // or now.
    const glm::vec3 offset =
        rest.restOffsets[p] + static_cast<float>(bestS) * (rest.restOffsets[to] - rest.restOffsets[p]);
    const Vec3 now = glm::mix(s.position[p], s.position[to], bestS);
    bool fair = true;
    for (auto t = incidence.begin(static_cast<ParticleIndex>(p));
         t != incidence.end(static_cast<ParticleIndex>(p)) && fair; ++t) {
      const Triangle& c = rest.triangles[*t];
      Vec3 r[3], y[3];
      for (int k = 0; k < 3; ++k) {
        r[k] = c[k] == p ? rest.restOrigin + Vec3(offset) : rest.restPosition(c[k]);
        y[k] = c[k] == p ? now : s.position[c[k]];
      }
      const Vec3 restFacing = glm::cross(rest.restPosition(c[1]) - rest.restPosition(c[0]),
                                         rest.restPosition(c[2]) - rest.restPosition(c[0]));
      const Vec3 nowFacing = glm::cross(s.position[c[1]] - s.position[c[0]], s.position[c[2]] - s.position[c[0]]);
      const Real least = kLeastChildArea * cloth.spacing * cloth.spacing * glm::length(restFacing);
      if (!(glm::dot(glm::cross(r[1] - r[0], r[2] - r[0]), restFacing) > least) ||
          !(glm::dot(glm::cross(y[1] - y[0], y[2] - y[0]), nowFacing) > 0.0))
        fair = false;
      const Real after = smallestAngleOf(r);
      if (after < kSnapLeastAngle && after < smallestAngle(rest, c[0], c[1], c[2])) fair = false;
    }
    if (!fair) continue;
    rest.restOffsets[p] = offset;
    s.position[p] = now;
    s.previousPosition[p] = glm::mix(s.previousPosition[p], s.previousPosition[to], bestS);
    if (!s.velocity.empty()) s.velocity[p] = glm::mix(s.velocity[p], s.velocity[to], bestS);
    distance[p] = 0.0;
    opening.moved.push_back(static_cast<ParticleIndex>(p));
    // Its triangles' rest areas follow (they share masses out when particles split).
    for (auto t = incidence.begin(static_cast<ParticleIndex>(p)); t != incidence.end(static_cast<ParticleIndex>(p));
         ++t)
      topology.triangleArea[*t] = triangleArea(rest, rest.triangles[*t]);
  }
  // Where the plane clips a corner of a small triangle (one an earlier cut left), its two
  // crossings lie close together and the corner's child would be a sliver: two crossings of one
  // triangle closer than kMergeChord spacings at rest share one particle, halfway between them (on
  // the plane still, and off each edge by at most half that). The triangle then loses the corner's
  // child, which its neighbours across the two edges cover, and the cut passes through the shared
  // particle. Not where the corner has no neighbour across either edge (it would be left in no
  // triangle); and where a child would turn over or keep almost no area, at rest or now (a
  // neighbour with an angle under about 25 degrees beside the crossing), the two stay apart and
  // all is made again: a guard, which some 8,000 random swipes over lattices never needed.
  const auto crossingIndex = [&](ParticleIndex p, ParticleIndex q) -> std::int64_t {
    const auto found = std::lower_bound(crossing.begin(), crossing.end(), std::pair{key(p, q), ParticleIndex{0}});
    return found != crossing.end() && found->first == key(p, q) ? found - crossing.begin() : -1;
  };
  const auto crossingRest = [&](std::size_t k) {
    const auto p = static_cast<ParticleIndex>(crossing[k].first >> 32);
    const auto q = static_cast<ParticleIndex>(crossing[k].first & 0xffffffffu);
    return glm::mix(rest.restPosition(p), rest.restPosition(q), crossingAt(p, q));
  };
  const auto pointOn = [&](ParticleIndex p, ParticleIndex q) -> std::int64_t {
    const std::int64_t k = crossingIndex(p, q);
    return k >= 0 ? static_cast<std::int64_t>(crossing[static_cast<std::size_t>(k)].second) : -1;
  };
  const Real mergeChord = kMergeChord * cloth.spacing;
  std::vector<std::uint8_t> apart(crossing.size(), 0);  // crossings that keep a particle each
  std::vector<std::int64_t> partner(crossing.size());
  std::vector<std::size_t> crossingOf;  // per new particle, the (first) crossing it stands for
  std::vector<Split> split;
  struct OnEdge {  // an edge of the mesh as it was that lies on the cut: both ends on it
    std::uint32_t triangle;
    int edge;
  };
  std::vector<OnEdge> onEdge;
  for (int attempt = 0;; ++attempt) {
    std::fill(partner.begin(), partner.end(), -1);
    if (attempt < kMergeAttempts) {
      for (std::uint32_t t = 0; t < t0; ++t) {
        const Triangle c = rest.triangles[t];
        for (int k = 0; k < 3; ++k) {
          const std::int64_t a = crossingIndex(c[k], c[(k + 1) % 3]), b = crossingIndex(c[(k + 1) % 3], c[(k + 2) % 3]);
          if (a < 0 || b < 0) continue;
          // The corner between them keeps triangles only through the neighbours across the two
          // edges: with neither (a corner of the border) it would be left in none.
          if (topology.neighbour[t][static_cast<std::size_t>(k)] < 0 &&
              topology.neighbour[t][static_cast<std::size_t>((k + 1) % 3)] < 0)
            continue;
          const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
          if (partner[ua] >= 0 || partner[ub] >= 0 || apart[ua] || apart[ub]) continue;
          if (!(glm::length(crossingRest(ua) - crossingRest(ub)) < mergeChord)) continue;
          partner[ua] = b;
          partner[ub] = a;
        }
      }
    }
    // The new particles: one per crossing, or one per two that share.
    std::size_t made = 0;
    crossingOf.clear();
    for (std::size_t k = 0; k < crossing.size(); ++k) {
      const std::int64_t other = partner[k];
      if (other >= 0 && static_cast<std::size_t>(other) < k) {
        crossing[k].second = crossing[static_cast<std::size_t>(other)].second;
        continue;
      }
      const auto p = static_cast<ParticleIndex>(crossing[k].first >> 32);
      const auto q = static_cast<ParticleIndex>(crossing[k].first & 0xffffffffu);
      const Real at = crossingAt(p, q);
      const ParticleIndex particle = insertParticle(cloth, p, q, at);
      crossing[k].second = particle;
      inserted.push_back({p, q, at, particle});
      crossingOf.push_back(k);
      ++made;
      if (other < 0) continue;
      // Halfway to the partner's crossing, at rest and now.
      const auto o = static_cast<std::size_t>(other);
      const auto p2 = static_cast<ParticleIndex>(crossing[o].first >> 32);
      const auto q2 = static_cast<ParticleIndex>(crossing[o].first & 0xffffffffu);
      const Real at2 = crossingAt(p2, q2);
      const glm::vec3 offset2 =
          rest.restOffsets[p2] + static_cast<float>(at2) * (rest.restOffsets[q2] - rest.restOffsets[p2]);
      rest.restOffsets[particle] = 0.5f * (rest.restOffsets[particle] + offset2);
      s.position[particle] = 0.5 * (s.position[particle] + glm::mix(s.position[p2], s.position[q2], at2));
      s.previousPosition[particle] =
          0.5 * (s.previousPosition[particle] + glm::mix(s.previousPosition[p2], s.previousPosition[q2], at2));
      if (!s.velocity.empty())
        s.velocity[particle] = 0.5 * (s.velocity[particle] + glm::mix(s.velocity[p2], s.velocity[q2], at2));
      if (!(s.pinned[p2] && s.pinned[q2])) {  // pinned only where all four ends are
        s.pinned[particle] = 0;
        s.inverseMass[particle] = 1.0;
      }
    }
    // Split every triangle with a new particle on an edge; note the cut's edges.
    split.clear();
    onEdge.clear();
    for (std::uint32_t t = 0; t < t0; ++t) {
      const Triangle c = rest.triangles[t];
      std::array<std::int64_t, 3> x{};
      int count = 0;
      for (int k = 0; k < 3; ++k) {
        x[static_cast<std::size_t>(k)] = pointOn(c[k], c[(k + 1) % 3]);
        if (x[static_cast<std::size_t>(k)] >= 0) ++count;
      }
      if (count == 0) {
        for (int k = 0; k < 3; ++k) {
          if (onCut(c[k]) && onCut(c[(k + 1) % 3]) && sideOf(c[(k + 2) % 3]) != 0) onEdge.push_back({t, k});
        }
        continue;
      }
      Split sp;
      sp.parent = t;
      sp.corners = c;
      sp.neighbour = topology.neighbour[t];
      using F = std::array<std::int8_t, 3>;
      if (count == 2) {
        // Edges i and i + 1 cut: corner i + 1 is alone on its side.
        int i = 0;
        while (!(x[static_cast<std::size_t>(i)] >= 0 && x[static_cast<std::size_t>((i + 1) % 3)] >= 0)) ++i;
        const int j = (i + 1) % 3, m = (i + 2) % 3;
        const auto xi = static_cast<ParticleIndex>(x[static_cast<std::size_t>(i)]);
        const auto xj = static_cast<ParticleIndex>(x[static_cast<std::size_t>(j)]);
        const ParticleIndex lone = c[j], next = c[m], first = c[i];
        if (xi == xj) {
          // The two crossings share a particle: the corner's child is gone, the quad a triangle.
          sp.children.push_back({Triangle(xj, next, first), F{static_cast<std::int8_t>(j), static_cast<std::int8_t>(m),
                                                              static_cast<std::int8_t>(i)}});
          split.push_back(std::move(sp));
          continue;
        }
        sp.children.push_back(
            {Triangle(xi, lone, xj), F{static_cast<std::int8_t>(i), static_cast<std::int8_t>(j), -1}});
        // The rest, a quad xj next first xi, along whichever diagonal leaves the larger smallest angle.
        const Real viaFirst = std::min(smallestAngle(rest, xj, next, first), smallestAngle(rest, xj, first, xi));
        const Real viaNext = std::min(smallestAngle(rest, xj, next, xi), smallestAngle(rest, next, first, xi));
        if (viaFirst >= viaNext) {
          sp.children.push_back(
              {Triangle(xj, next, first), F{static_cast<std::int8_t>(j), static_cast<std::int8_t>(m), -1}});
          sp.children.push_back({Triangle(xj, first, xi), F{-1, static_cast<std::int8_t>(i), -1}});
          sp.cutEdgeChild = 2;
          sp.cutEdge = 2;
        } else {
          sp.children.push_back({Triangle(xj, next, xi), F{static_cast<std::int8_t>(j), -1, -1}});
          sp.children.push_back(
              {Triangle(next, first, xi), F{static_cast<std::int8_t>(m), static_cast<std::int8_t>(i), -1}});
          sp.cutEdgeChild = 1;
          sp.cutEdge = 2;
        }
      } else if (count == 1) {
        int i = 0;
        while (x[static_cast<std::size_t>(i)] < 0) ++i;
        const int j = (i + 1) % 3, m = (i + 2) % 3;
        const auto xi = static_cast<ParticleIndex>(x[static_cast<std::size_t>(i)]);
        const ParticleIndex opposite = c[m];
        sp.children.push_back(
            {Triangle(c[i], xi, opposite), F{static_cast<std::int8_t>(i), -1, static_cast<std::int8_t>(m)}});
        sp.children.push_back(
            {Triangle(xi, c[j], opposite), F{static_cast<std::int8_t>(i), static_cast<std::int8_t>(j), -1}});
        // The cut runs on to the opposite corner where that is on the cut (or where the last segment
        // left it); else the swipe ends (or starts) inside this triangle, at xi.
        if (onCut(opposite) || (opposite < n0 && line.joins[opposite])) {
          sp.cutEdgeChild = 0;
          sp.cutEdge = 1;
        }
      } else {
        continue;  // three: cannot happen (a plane crosses at most two edges of a triangle)
      }
      split.push_back(std::move(sp));
    }
    // A shared particle off the edges it stands for must leave every child facing the way its
    // parent did, with an area; where one does not, its two crossings stay apart and all is made again.
    bool turned = false;
    for (const Split& sp : split) {
      const Triangle& c = sp.corners;
      const Vec3 facing = glm::cross(rest.restPosition(c[1]) - rest.restPosition(c[0]),
                                     rest.restPosition(c[2]) - rest.restPosition(c[0]));
      const Real size = glm::length(facing);
      for (const Split::Child& child : sp.children) {
        bool shared = false;
        for (int k = 0; k < 3; ++k) {
          const ParticleIndex p = child.corners[k];
          if (p < n0) continue;
          const std::size_t at = crossingOf[p - n0];
          if (partner[at] >= 0) shared = true;
        }
        if (!shared) continue;
        const Vec3 n = glm::cross(rest.restPosition(child.corners[1]) - rest.restPosition(child.corners[0]),
                                  rest.restPosition(child.corners[2]) - rest.restPosition(child.corners[0]));
        const Vec3 nowFacing = glm::cross(s.position[c[1]] - s.position[c[0]], s.position[c[2]] - s.position[c[0]]);
        const Vec3 nowChild = glm::cross(s.position[child.corners[1]] - s.position[child.corners[0]],
                                         s.position[child.corners[2]] - s.position[child.corners[0]]);
        if (glm::dot(n, facing) > kLeastMergedArea * size * cloth.spacing * cloth.spacing &&
            glm::dot(nowChild, nowFacing) > 0.0)
          continue;
        for (int k = 0; k < 3; ++k) {
          const ParticleIndex p = child.corners[k];
          if (p < n0) continue;
          const std::size_t at = crossingOf[p - n0];
          if (partner[at] < 0) continue;
          apart[at] = apart[static_cast<std::size_t>(partner[at])] = 1;
          turned = true;
        }
      }
    }
    if (!turned) {
      particleBudget -= made;
      break;
    }
    truncateParticles(cloth, n0);
    inserted.resize(insertedBefore);
  }
  // The constraints the split triangles witness, as particle pairs, to be found again in their children.
  std::vector<std::uint8_t> isParent(t0, 0);
  for (const Split& sp : split) isParent[sp.parent] = 1;
  struct Pair {
    ConstraintKind kind;
    ParticleIndex a, b;
    RestReal restLength;
  };
  std::vector<Pair> again;
  for (ConstraintTemplate& x : topology.templates) {
    if (x.link == ConstraintTemplate::Link::free || (!isParent[x.t1] && !isParent[x.t2])) continue;
    const Triangle& c1 = rest.triangles[x.t1];
    const Triangle& c2 = rest.triangles[x.t2];
    bool alive = true;
    if (x.link == ConstraintTemplate::Link::across) {
      alive = topology.neighbour[x.t1][x.middle1] == static_cast<std::int32_t>(x.t2);
    } else if (x.link == ConstraintTemplate::Link::through) {
      alive = c1[x.middle1] == c2[x.middle2];
    }
    if (alive) again.push_back({x.kind, c1[x.corner1], c2[x.corner2], x.restLength});
    x.link = ConstraintTemplate::Link::free;  // this recipe is gone; the pair is found again below
    x.broken = true;
    x.t1 = x.t2 = 0;
  }
  // Each new particle's mass, from the nearer end of its edge: as much as that end holds per unit
  // of area, times a third of the area of the triangles around the new particle. (One giver a
  // particle keeps the mass exactly what it was: takeShare.)
  std::vector<Real> giverArea(inserted.size(), 0.0);
  for (std::size_t k = insertedBefore; k < inserted.size(); ++k) {
    const ParticleInsert& in = inserted[k];
    const ParticleIndex giver = in.s < 0.5 ? in.a : in.b;
    for (auto t = incidence.begin(giver); t != incidence.end(giver); ++t)
      giverArea[k] += topology.triangleArea[*t] / 3.0;
  }
  // Put the children in: the first in the parent's place, the others at the end.
  for (Split& sp : split) {
    for (std::size_t k = 0; k < sp.children.size(); ++k) {
      Split::Child& child = sp.children[k];
      if (k == 0) {
        child.index = sp.parent;
        rest.triangles[sp.parent] = child.corners;
      } else {
        child.index = static_cast<std::uint32_t>(rest.triangles.size());
        rest.triangles.push_back(child.corners);
      }
    }
  }
  const std::size_t t1 = rest.triangles.size();
  topology.neighbour.resize(t1, {-1, -1, -1});
  topology.triangleArea.resize(t1);
  std::vector<Real> insertedArea(rest.particleCount() - n0, 0.0);
  for (const Split& sp : split) {
    for (const Split::Child& child : sp.children) {
      const Real area = triangleArea(rest, child.corners);
      topology.triangleArea[child.index] = area;
      for (int k = 0; k < 3; ++k) {
        if (child.corners[k] >= n0) insertedArea[child.corners[k] - n0] += area / 3.0;
      }
    }
  }
  for (std::size_t k = insertedBefore; k < inserted.size(); ++k) {
    const ParticleInsert& in = inserted[k];
    const ParticleIndex giver = in.s < 0.5 ? in.a : in.b;
    const Real wanted = giverArea[k] > 0.0
                            ? static_cast<Real>(s.mass[giver]) * insertedArea[in.particle - n0] / giverArea[k]
                            : 0.5 * static_cast<Real>(s.mass[giver]);
    const MassReal share = takeShare(s.mass[giver], wanted > 0.0 ? wanted : 0.5 * static_cast<Real>(s.mass[giver]));
    s.mass[in.particle] = share;
    if (s.inverseMass[in.particle] > 0.0) s.inverseMass[in.particle] = 1.0 / share;
    if (s.inverseMass[giver] > 0.0) s.inverseMass[giver] = 1.0 / s.mass[giver];
  }
  // Join the children to each other and to their parents' neighbours, across the edges that were joined.
  std::vector<EdgeUse> uses;
  for (const Split& sp : split) {
    for (const Split::Child& child : sp.children) {
      topology.neighbour[child.index] = {-1, -1, -1};
      for (int k = 0; k < 3; ++k) {
        const std::int8_t from = child.from[static_cast<std::size_t>(k)];
        if (from >= 0 && sp.neighbour[static_cast<std::size_t>(from)] < 0) continue;
        uses.push_back({key(child.corners[k], child.corners[(k + 1) % 3]), child.index, k});
      }
    }
    for (int k = 0; k < 3; ++k) {
      const std::int32_t other = sp.neighbour[static_cast<std::size_t>(k)];
      if (other < 0 || isParent[static_cast<std::size_t>(other)]) continue;
      // A neighbour left whole: its edge to the parent goes to whichever child has that edge now.
      auto& back = topology.neighbour[static_cast<std::size_t>(other)];
      for (int e = 0; e < 3; ++e) {
        if (back[static_cast<std::size_t>(e)] != static_cast<std::int32_t>(sp.parent)) continue;
        back[static_cast<std::size_t>(e)] = -1;
        const Triangle& o = rest.triangles[static_cast<std::size_t>(other)];
        uses.push_back({key(o[e], o[(e + 1) % 3]), static_cast<std::uint32_t>(other), e});
      }
    }
  }
  joinAlongEdges(topology, uses);
  // Sever the cut: the children's edge along it, and the old edges with both ends on it that part
  // triangles on opposite sides.
  for (const Split& sp : split) {
    if (sp.cutEdgeChild < 0) continue;
    const Split::Child& child = sp.children[static_cast<std::size_t>(sp.cutEdgeChild)];
    opening.touched.push_back(child.corners[sp.cutEdge]);
    opening.touched.push_back(child.corners[(sp.cutEdge + 1) % 3]);
    sever(topology, child.index, sp.cutEdge);
    opening.changed = true;
  }
  for (const OnEdge& e : onEdge) {
    const std::int32_t other = topology.neighbour[e.triangle][static_cast<std::size_t>(e.edge)];
    if (other < 0) continue;
    const Triangle& t = rest.triangles[e.triangle];
    const Triangle& o = rest.triangles[static_cast<std::size_t>(other)];
    const ParticleIndex p = t[e.edge], q = t[(e.edge + 1) % 3];
    ParticleIndex far = o[0];
    for (int k = 0; k < 3; ++k) {
      if (o[k] != p && o[k] != q) far = o[k];
    }
    if (sideOf(t[(e.edge + 2) % 3]) * sideOf(far) >= 0) continue;
    opening.touched.push_back(p);
    opening.touched.push_back(q);
    sever(topology, e.triangle, e.edge);
    opening.changed = true;
  }
  if (!split.empty() || !opening.moved.empty()) opening.changed = true;
  // The constraints again, over the children, and one along every new edge.
  const Incidence after(rest.triangles, rest.particleCount());
  for (const Pair& pair : again) {
    addTemplates(topology, rest, after, pair.kind, {pair.a, pair.b, pair.restLength}, false);
  }
  // The links of the children's new edges (those with a particle the split made), by the rules
  // constrainMesh makes a mesh's by (meshConstraints): a particle made here stands for no lattice
  // node, so each is stretch. One recipe for each child an edge is on: it lives while one of them
  // has it.
  std::vector<glm::uvec3> children;
  for (const Split& sp : split) {
    for (const Split::Child& child : sp.children)
      children.push_back({child.corners[0], child.corners[1], child.corners[2]});
  }
  std::vector<std::pair<std::uint64_t, RestReal>> made;  // (edge key, rest length), sorted
  if (!children.empty()) {
    const std::vector<glm::ivec2> none(rest.particleCount(), kNoNode);
    const auto links = meshConstraints(rest, children, none, {true, false, false});
    for (const DistanceConstraint& c : links[static_cast<std::size_t>(ConstraintKind::stretch)]) {
      if (c.a >= n0 || c.b >= n0) made.push_back({key(c.a, c.b), c.restLength});
    }
    std::sort(made.begin(), made.end());
  }
  for (const Split& sp : split) {
    for (const Split::Child& child : sp.children) {
      for (int k = 0; k < 3; ++k) {
        const ParticleIndex p = child.corners[k], q = child.corners[(k + 1) % 3];
        const auto link = std::lower_bound(made.begin(), made.end(), std::pair{key(p, q), RestReal{0}});
        if (link == made.end() || link->first != key(p, q)) continue;
        ConstraintTemplate x;
        x.kind = ConstraintKind::stretch;
        x.restLength = link->second;
        x.link = ConstraintTemplate::Link::same;
        x.t1 = x.t2 = child.index;
        x.corner1 = static_cast<std::uint8_t>(k);
        x.corner2 = static_cast<std::uint8_t>((k + 1) % 3);
        topology.templates.push_back(x);
      }
    }
  }
}

// The smallest angle a flip must lift the pair's smallest angle past, and by how much (radians).
constexpr Real kFlipBelow = 25.0 * 3.14159265358979323846 / 180.0;
constexpr Real kFlipGain = 1e-3;
constexpr int kFlipPasses = 8;
// A quad flips only where it lies flat now: its two triangles' normals within this cosine.
constexpr Real kFlipFlat = 0.996;  // about 5 degrees

// Flips the edges between the triangles around `around` (and one ring beyond) where the other
// diagonal of their quad gives a larger smallest angle at rest (the max-min rule that leads to a
// Delaunay mesh), so that slivers a cut or tear leaves beside its border (two cuts meeting at a
// small angle, a snapped particle) become fair triangles where the mesh around allows. Only edges
// still joined flip, so the border stays where the cuts put it; only quads convex at rest and
// flat now (the surface does not change shape), so no triangle turns over. The stretch link along
// the edge moves to the new one; a shear link on the new one (a lattice's other diagonal) moves to
// the old. A flip that would leave another link of its corners without a triangle to witness it
// (a neighbouring quad's diagonal, a bend through a corner: addTemplates) is undone, so every
// link still breaks where the cloth is cut or torn.
void flipAround(Cloth& cloth, const std::vector<ParticleIndex>& around) {
  ClothRest& rest = cloth.rest;
  Topology& topology = cloth.topology;
  const std::vector<Vec3>& x = cloth.state.position;
  const std::size_t n = rest.particleCount();
  std::vector<std::uint8_t> near(n, 0);
  for (const ParticleIndex p : around) {
    if (p < n) near[p] = 1;
  }
  // Each particle's triangles, kept up as triangles flip; each particle's links (kind, index).
  std::vector<std::vector<std::uint32_t>> fan(n);
  for (std::uint32_t t = 0; t < rest.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) fan[rest.triangles[t][k]].push_back(t);
  }
  std::vector<std::vector<std::pair<std::uint8_t, std::uint32_t>>> links(n);
  for (std::size_t k = 0; k < kConstraintKindCount; ++k) {
    for (std::uint32_t j = 0; j < rest.constraints[k].size(); ++j) {
      const DistanceConstraint& c = rest.constraints[k][j];
      links[c.a].push_back({static_cast<std::uint8_t>(k), j});
      links[c.b].push_back({static_cast<std::uint8_t>(k), j});
    }
  }
  const auto has = [&](std::uint32_t t, ParticleIndex q) { return cornerOf(rest.triangles[t], q) >= 0; };
  // As addTemplates finds a witness: p and q in one triangle, in two joined across an edge, or
  // each in a triangle with a middle particle.
  const auto witnessed = [&](ParticleIndex p, ParticleIndex q) {
    for (const std::uint32_t t : fan[p]) {
      if (has(t, q)) return true;
      for (const std::int32_t o : topology.neighbour[t]) {
        if (o >= 0 && has(static_cast<std::uint32_t>(o), q)) return true;
      }
      for (int m = 0; m < 3; ++m) {
        const ParticleIndex middle = rest.triangles[t][m];
        if (middle == p) continue;
        for (const std::uint32_t u : fan[middle]) {
          if (has(u, q)) return true;
        }
      }
    }
    return false;
  };
  const auto normal = [&](auto&& at, ParticleIndex a, ParticleIndex b, ParticleIndex c) {
    return glm::cross(at(b) - at(a), at(c) - at(a));
  };
  const auto restAt = [&](ParticleIndex p) { return rest.restPosition(p); };
  const auto nowAt = [&](ParticleIndex p) { return x[p]; };
  const auto unit = [](Vec3 v) {
    const Real l = glm::length(v);
    return l > 0.0 ? v / l : Vec3{0.0};
  };
  const auto erase = [](std::vector<std::uint32_t>& list, std::uint32_t t) {
    list.erase(std::find(list.begin(), list.end(), t));
  };
  // Replaces triangle t by `corners` and o by `cornersO`, their neighbours and the fans following.
  const auto setPair = [&](std::uint32_t t, Triangle corners, std::array<std::int32_t, 3> nt, std::uint32_t o,
                           Triangle cornersO, std::array<std::int32_t, 3> no) {
    for (const std::uint32_t u : {t, o}) {
      for (int k = 0; k < 3; ++k) erase(fan[rest.triangles[u][k]], u);
    }
    rest.triangles[t] = corners;
    rest.triangles[o] = cornersO;
    topology.neighbour[t] = nt;
    topology.neighbour[o] = no;
    // The triangles across from the pair point back, edge by edge, at whichever of the two has it now.
    for (const std::uint32_t u : {t, o}) {
      const Triangle& cu = rest.triangles[u];
      for (int k = 0; k < 3; ++k) {
        fan[cu[k]].push_back(u);
        const std::int32_t w = topology.neighbour[u][static_cast<std::size_t>(k)];
        if (w < 0 || static_cast<std::uint32_t>(w) == t || static_cast<std::uint32_t>(w) == o) continue;
        const Triangle& cw = rest.triangles[static_cast<std::size_t>(w)];
        for (int e = 0; e < 3; ++e) {
          if (std::minmax(cw[e], cw[(e + 1) % 3]) == std::minmax(cu[k], cu[(k + 1) % 3]))
            topology.neighbour[static_cast<std::size_t>(w)][static_cast<std::size_t>(e)] = static_cast<std::int32_t>(u);
        }
      }
    }
    topology.triangleArea[t] = triangleArea(rest, rest.triangles[t]);
    topology.triangleArea[o] = triangleArea(rest, rest.triangles[o]);
  };
  const auto same = [](const DistanceConstraint& l, ParticleIndex p, ParticleIndex q) {
    return (l.a == p && l.b == q) || (l.a == q && l.b == p);
  };
  for (int pass = 0; pass < kFlipPasses; ++pass) {
    std::vector<std::uint32_t> candidates;
    for (std::size_t p = 0; p < n; ++p) {
      if (!near[p]) continue;
      for (const std::uint32_t t : fan[p]) {
        candidates.push_back(t);
        for (const std::int32_t o : topology.neighbour[t]) {
          if (o >= 0) candidates.push_back(static_cast<std::uint32_t>(o));
        }
      }
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    bool flipped = false;
    for (const std::uint32_t t : candidates) {
      for (int k = 0; k < 3; ++k) {
        const std::int32_t other = topology.neighbour[t][static_cast<std::size_t>(k)];
        if (other < 0 || static_cast<std::uint32_t>(other) < t) continue;
        const auto o = static_cast<std::uint32_t>(other);
        const Triangle tt = rest.triangles[t], to = rest.triangles[o];
        const ParticleIndex a = tt[k], b = tt[(k + 1) % 3], c = tt[(k + 2) % 3];
        int ko = 0;
        while (ko < 3 && !(to[ko] == b && to[(ko + 1) % 3] == a)) ++ko;
        if (ko == 3) continue;  // joined the other way round: leave it
        const ParticleIndex d = to[(ko + 2) % 3];
        if (c == d) continue;
        const Real before = std::min(smallestAngle(rest, a, b, c), smallestAngle(rest, b, a, d));
        if (!(before < kFlipBelow)) continue;
        const Real after = std::min(smallestAngle(rest, a, d, c), smallestAngle(rest, d, b, c));
        if (!(after > before + kFlipGain)) continue;
        // Convex at rest: the new triangles face as the old did.
        const Vec3 facing = normal(restAt, a, b, c) + normal(restAt, b, a, d);
        if (!(glm::dot(normal(restAt, a, d, c), facing) > 0.0) || !(glm::dot(normal(restAt, d, b, c), facing) > 0.0))
          continue;
        // Flat and convex now.
        const Vec3 nt = unit(normal(nowAt, a, b, c)), no = unit(normal(nowAt, b, a, d));
        if (!(glm::dot(nt, no) > kFlipFlat) || !(glm::dot(unit(normal(nowAt, a, d, c)), nt + no) > 0.0) ||
            !(glm::dot(unit(normal(nowAt, d, b, c)), nt + no) > 0.0))
          continue;
        // Not an edge already (a triangle elsewhere with both c and d).
        if (std::any_of(fan[c].begin(), fan[c].end(), [&](std::uint32_t u) { return has(u, d); })) continue;
        // The links of the four corners a triangle witnesses now (but a-b, which moves).
        std::vector<std::pair<std::uint8_t, std::uint32_t>> kept;
        for (const ParticleIndex p : {a, b, c, d}) {
          for (const auto& link : links[p]) {
            const DistanceConstraint& l = rest.constraints[link.first][link.second];
            if (same(l, a, b) || same(l, c, d)) continue;
            if (witnessed(l.a, l.b)) kept.push_back(link);
          }
        }
        // t becomes (a, d, c) and o (d, b, c).
        const std::array<std::int32_t, 3> oldT = topology.neighbour[t], oldO = topology.neighbour[o];
        setPair(t, Triangle(a, d, c),
                {oldO[static_cast<std::size_t>((ko + 1) % 3)], static_cast<std::int32_t>(o),
                 oldT[static_cast<std::size_t>((k + 2) % 3)]},
                o, Triangle(d, b, c),
                {oldO[static_cast<std::size_t>((ko + 2) % 3)], oldT[static_cast<std::size_t>((k + 1) % 3)],
                 static_cast<std::int32_t>(t)});
        const bool lost = std::any_of(kept.begin(), kept.end(), [&](const auto& link) {
          const DistanceConstraint& l = rest.constraints[link.first][link.second];
          return !witnessed(l.a, l.b);
        });
        if (lost) {
          setPair(t, tt, oldT, o, to, oldO);
          continue;
        }
        // The links: stretch from a-b to c-d (or gone where c-d has one), a shear on c-d to a-b.
        auto& stretch = rest.constraints[static_cast<std::size_t>(ConstraintKind::stretch)];
        const auto linkOf = [&](ConstraintKind kind, ParticleIndex p, ParticleIndex q) -> std::int64_t {
          for (const auto& link : links[p]) {
            if (link.first == static_cast<std::uint8_t>(kind) && same(rest.constraints[link.first][link.second], p, q))
              return link.second;
          }
          return -1;
        };
        const auto relink = [&](ConstraintKind kind, std::uint32_t j, ParticleIndex from1, ParticleIndex from2,
                                ParticleIndex to1, ParticleIndex to2) {
          const auto k8 = static_cast<std::uint8_t>(kind);
          for (const ParticleIndex q : {from1, from2}) {
            auto& list = links[q];
            list.erase(std::find(list.begin(), list.end(), std::pair{k8, j}));
          }
          rest.constraints[static_cast<std::size_t>(kind)][j] = {std::min(to1, to2), std::max(to1, to2),
                                                                 toRestLength(restEdge(rest, to1, to2))};
          links[to1].push_back({k8, j});
          links[to2].push_back({k8, j});
        };
        const std::int64_t ab = linkOf(ConstraintKind::stretch, a, b);
        const std::int64_t cdShear = linkOf(ConstraintKind::shear, c, d);
        const bool cdStretch = linkOf(ConstraintKind::stretch, c, d) >= 0;
        if (cdShear >= 0) relink(ConstraintKind::shear, static_cast<std::uint32_t>(cdShear), c, d, a, b);
        if (ab >= 0 && !cdStretch) relink(ConstraintKind::stretch, static_cast<std::uint32_t>(ab), a, b, c, d);
        if (ab >= 0 && cdStretch) {
          // (Rare: c-d had a stretch link of its own.) The a-b one goes; the indices after it move down.
          stretch.erase(stretch.begin() + ab);
          for (auto& list : links) {
            list.erase(std::remove(list.begin(), list.end(),
                                   std::pair{static_cast<std::uint8_t>(ConstraintKind::stretch),
                                             static_cast<std::uint32_t>(ab)}),
                       list.end());
            for (auto& link : list) {
              if (link.first == static_cast<std::uint8_t>(ConstraintKind::stretch) &&
                  link.second > static_cast<std::uint32_t>(ab))
                --link.second;
            }
          }
        }
        flipped = true;
        break;  // t is another triangle now
      }
    }
    if (!flipped) break;
  }
}

// After openings: every particle whose fan fell apart splits, the constraints are made again, and
// those of particles moved onto a line take their new rest lengths.
void finishOpening(Cloth& cloth, Opening& opening, std::size_t particleBudget, std::vector<ParticleSplit>& splits) {
  ClothRest& rest = cloth.rest;
  Topology& topology = cloth.topology;
  const std::vector<ParticleIndex>& moved = opening.moved;
  std::vector<ParticleIndex> around = opening.touched;
  around.insert(around.end(), moved.begin(), moved.end());
  splitParticles(cloth, std::move(opening.touched), particleBudget, splits);
  for (std::size_t p = opening.firstNew; p < rest.particleCount(); ++p) around.push_back(static_cast<ParticleIndex>(p));
  rebuildConstraints(cloth);
  // A particle moved onto the cut (and its copies) is at a new rest distance from its neighbours.
  std::vector<std::uint8_t> shifted(rest.particleCount(), 0);
  for (const ParticleIndex p : moved) shifted[p] = 1;
  for (const ParticleSplit& made : splits) {
    if (made.original < shifted.size() && shifted[made.original]) shifted[made.copy] = 1;
  }
  if (!moved.empty()) {
    for (std::size_t k = 0; k < kConstraintKindCount; ++k) {
      for (std::size_t j = 0; j < rest.constraints[k].size(); ++j) {
        DistanceConstraint& c = rest.constraints[k][j];
        if (!shifted[c.a] && !shifted[c.b]) continue;
        const Real edge = restEdge(rest, c.a, c.b);
        if (!(edge > 0.0)) continue;
        c.restLength = toRestLength(edge);
        topology.templates[topology.source[k][j]].restLength = c.restLength;
      }
    }
  }
  flipAround(cloth, around);
  // Recipes afresh: those found again in split triangles may name other witnesses than a fresh
  // search (a snapshot loaded) finds. The rest frames are made again when next needed.
  makeTemplates(cloth);
  topology.restFrames.clear();
}

}  // namespace

bool cut(Cloth& cloth, Vec3 a, Vec3 b, Vec3 depth, std::size_t particleBudget, std::vector<ParticleSplit>& splits,
         std::vector<ParticleInsert>& inserted) {
  const Real length = glm::length(b - a);
  const Vec3 across = glm::cross(b - a, depth);
  if (!(length > 1e-12) || !(glm::length(across) > 1e-12 * length)) return false;
  const Vec3 along = (b - a) / length;
  const Vec3 normal = glm::normalize(across);
  build(cloth);
  Topology& topology = cloth.topology;
  const ParticleState& s = cloth.state;
  const std::size_t n0 = cloth.rest.particleCount();
  // A swipe is cut segment by segment; the segment before this one (when it ended where this one
  // starts) may have left the cut at tips inside the triangle this one starts in.
  std::vector<ParticleIndex> tips;
  if (topology.cutEnd == a) tips = topology.cutTips;
  topology.cutTips.clear();
  topology.cutEnd = b;
  const auto ahead = [&](Vec3 x) { return glm::dot(x - a, along); };  // m along the swipe from a
  const auto within = [&](Vec3 x) {
    const Real u = ahead(x);
    return u >= 0.0 && u <= length;
  };
  Line line(n0, cloth.spacing);
  for (const ParticleIndex p : tips) {
    if (p < n0) line.joins[p] = 1;
  }
  // A particle on the line counts within the swipe up to kOnLine spacings past either end, as it
  // does off the plane: a swipe along edges that stops just short of a particle still reaches it
  // (a slit of one edge between two particles inside the cloth opens nothing).
  const auto reaches = [&](Vec3 x) {
    const Real u = ahead(x);
    return u >= -line.onLine && u <= length + line.onLine;
  };
  for (std::size_t p = 0; p < n0; ++p) {
    line.place(p, glm::dot(s.position[p] - a, normal));
    // A point of the cut on a particle: one on the line, within the swipe (or where the last segment left off).
    line.onCut[p] = line.side[p] == 0 && (reaches(s.position[p]) || line.joins[p]);
  }
  line.counts = [&](ParticleIndex p, ParticleIndex q, Real at) {
    return within(glm::mix(s.position[p], s.position[q], at));
  };
  const std::vector<std::uint8_t> onCut = line.onCut;
  Opening opening;
  opening.firstNew = n0;
  openAlong(cloth, line, nullptr, particleBudget, inserted, opening);
  // A link no triangle witnesses (a chain) breaks where the cut crosses it.
  for (ConstraintTemplate& x : topology.templates) {
    if (x.link != ConstraintTemplate::Link::free || x.broken) continue;
    const Vec3 xa = s.position[x.t1], xb = s.position[x.t2];
    const Real da = glm::dot(xa - a, normal), db = glm::dot(xb - a, normal);
    if ((da >= 0.0) == (db >= 0.0) || !within(xa + (xb - xa) * (da / (da - db)))) continue;
    x.broken = true;
    ++topology.torn;
    opening.changed = true;
  }
  // The points of the cut near this segment's end are where the next segment of the swipe carries
  // it on from: tips left by earlier segments, particles on the cut and the new ones.
  const auto nearEnd = [&](ParticleIndex p) { return std::abs(ahead(s.position[p]) - length) <= 1.5 * cloth.spacing; };
  for (const ParticleIndex p : tips) {
    if (p < s.position.size() && nearEnd(p)) topology.cutTips.push_back(p);
  }
  for (std::size_t p = 0; p < n0; ++p) {
    if (onCut[p] && nearEnd(static_cast<ParticleIndex>(p))) topology.cutTips.push_back(static_cast<ParticleIndex>(p));
  }
  for (const ParticleInsert& in : inserted) {
    if (nearEnd(in.particle)) topology.cutTips.push_back(in.particle);
  }
  std::sort(topology.cutTips.begin(), topology.cutTips.end());
  topology.cutTips.erase(std::unique(topology.cutTips.begin(), topology.cutTips.end()), topology.cutTips.end());
  if (!opening.changed) return false;
  finishOpening(cloth, opening, particleBudget, splits);
  return true;
}

namespace {

// How a triangle is stretched: C = F^T F of its deformation gradient F (rest to now), as a
// symmetric 3 x 3 tensor in rest space (xx, yy, zz, xy, xz, yz), and its largest principal stretch.
struct Stretch {
  std::array<Real, 6> tensor{};
  Real largest = 0.0;
};

Topology::RestFrame restFrame(const ClothRest& rest, const Triangle& t) {
  const Vec3 e1 = rest.restPosition(t[1]) - rest.restPosition(t[0]);
  const Vec3 e2 = rest.restPosition(t[2]) - rest.restPosition(t[0]);
  const Real l1 = glm::length(e1);
  const Vec3 n = glm::cross(e1, e2);
  if (!(l1 > 0.0) || !(glm::length(n) > 0.0)) return {glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, 0.0f, 0.0f};
  const Vec3 u = e1 / l1, w = glm::normalize(glm::cross(n, u));
  return {glm::vec3(u), glm::vec3(w), static_cast<float>(l1), static_cast<float>(glm::dot(u, e2)),
          static_cast<float>(glm::dot(w, e2))};
}

Stretch triangleStretch(const Cloth& cloth, const Triangle& t, const Topology::RestFrame& frame,
                        bool withTensor = true) {
  if (!(frame.a > 0.0f) || !(frame.d != 0.0f)) return {};
  const std::vector<Vec3>& x = cloth.state.position;
  const Vec3 u(frame.u), w(frame.w);
  const Real a = frame.a, b = frame.b, d = frame.d;  // Dm = [[a, b], [0, d]]
  const Vec3 s1 = x[t[1]] - x[t[0]], s2 = x[t[2]] - x[t[0]];
  // F = Ds Dm^-1: its columns, the images of u and w.
  const Vec3 fu = s1 / a, fw = (s2 - b * fu) / d;
  const Real cuu = glm::dot(fu, fu), cww = glm::dot(fw, fw), cuw = glm::dot(fu, fw);
  Stretch out;
  const Real half = 0.5 * (cuu + cww), gap = std::sqrt(0.25 * (cuu - cww) * (cuu - cww) + cuw * cuw);
  out.largest = std::sqrt(std::max(half + gap, 0.0));
  if (!withTensor) return out;
  // C in rest space: cuu u u^T + cww w w^T + cuw (u w^T + w u^T).
  const auto entry = [&](int i, int j) {
    return cuu * u[i] * u[j] + cww * w[i] * w[j] + cuw * (u[i] * w[j] + w[i] * u[j]);
  };
  out.tensor = {entry(0, 0), entry(1, 1), entry(2, 2), entry(0, 1), entry(0, 2), entry(1, 2)};
  return out;
}

// The largest eigenvalue of a symmetric tensor and its unit eigenvector, by power iteration from `start`.
Real largestEigen(const std::array<Real, 6>& m, Vec3 start, Vec3& direction) {
  const auto apply = [&](Vec3 v) {
    return Vec3{m[0] * v.x + m[3] * v.y + m[4] * v.z, m[3] * v.x + m[1] * v.y + m[5] * v.z,
                m[4] * v.x + m[5] * v.y + m[2] * v.z};
  };
  Vec3 v = glm::length(start) > 0.0 ? glm::normalize(start) : Vec3{1.0, 0.0, 0.0};
  for (int k = 0; k < 24; ++k) {
    const Vec3 next = apply(v);
    const Real length = glm::length(next);
    if (!(length > 0.0)) break;
    v = next / length;
  }
  direction = v;
  return glm::dot(v, apply(v));
}

constexpr int kTearPasses = 8;   // breaking passes a step at most, the cloth relaxed between them
constexpr int kRelaxSweeps = 4;  // Gauss-Seidel sweeps over the stretch links near a fresh crack
constexpr int kRelaxRings = 3;   // ... within this many rings of triangles of it
// A crack's tip: a particle on a border whose triangles span more than this around it (the rest of
// the turn is the slit).
constexpr Real kTipAngle = 1.5 * 3.14159265358979323846;
// The triangles whose stretch sets the way a tip runs: those whose centres lie within this many
// spacings of it at rest (two rings of triangles, about 1.5 spacings, before; 4 straightened
// cracks less, 6 more but at a cost elsewhere; docs/design.md).
constexpr Real kTipReach = 5.0;
// No crack starts within this many spacings of a tip: the flanks just behind a running crack's tip
// are stretched as it opens, and a crack started there is a branch (docs/design.md).
constexpr Real kStartClear = 8.0;

// Breaks the fan of particle v along the line through it perpendicular to `pull` (rest space): on
// both sides where v lies inside the cloth, else on the side that runs into the cloth, away from
// the border (a crack's tip runs on ahead). Returns whether it opened anything.
bool breakAt(Cloth& cloth, ParticleIndex v, Vec3 pull, const Incidence& incidence, std::size_t& particleBudget,
             std::vector<ParticleInsert>& inserted, Opening& opening) {
  const ClothRest& rest = cloth.rest;
  const Topology& topology = cloth.topology;
  const std::size_t n0 = rest.particleCount();
  const Vec3 at = rest.restPosition(v);
  std::vector<std::uint32_t> fan(incidence.begin(v), incidence.end(v));
  if (fan.empty()) return false;
  Vec3 normal{0.0};
  std::vector<Vec3> border;  // directions of the border edges at v
  for (const std::uint32_t t : fan) {
    const Triangle& c = rest.triangles[t];
    normal += glm::cross(rest.restPosition(c[1]) - rest.restPosition(c[0]),
                         rest.restPosition(c[2]) - rest.restPosition(c[0]));
    const int cv = cornerOf(c, v);
    if (topology.neighbour[t][static_cast<std::size_t>(cv)] < 0)
      border.push_back(rest.restPosition(c[(cv + 1) % 3]) - at);
    if (topology.neighbour[t][static_cast<std::size_t>((cv + 2) % 3)] < 0)
      border.push_back(rest.restPosition(c[(cv + 2) % 3]) - at);
  }
  if (!(glm::length(normal) > 0.0) || !(glm::length(pull) > 0.0)) return false;
  normal = glm::normalize(normal);
  pull = glm::normalize(pull - glm::dot(pull, normal) * normal);
  const Vec3 crack = glm::normalize(glm::cross(normal, pull));
  // Which way the crack runs: both ways from inside the cloth; from a border, the way into the
  // cloth (inside one of v's triangles) farthest from the border's edges.
  Real way = 0.0;  // 0: both; else +1 or -1 along `crack`
  if (!border.empty()) {
    Real best = 2.0;
    for (const Real sign : {1.0, -1.0}) {
      const Vec3 ray = sign * crack;
      bool inside = false;
      for (const std::uint32_t t : fan) {
        const Triangle& c = rest.triangles[t];
        const int cv = cornerOf(c, v);
        const Vec3 p = rest.restPosition(c[(cv + 1) % 3]) - at, q = rest.restPosition(c[(cv + 2) % 3]) - at;
        if (glm::dot(glm::cross(p, ray), normal) >= 0.0 && glm::dot(glm::cross(ray, q), normal) >= 0.0) inside = true;
      }
      if (!inside) continue;
      Real closest = -1.0;  // the largest cosine to a border edge
      for (const Vec3& b : border) closest = std::max(closest, glm::dot(ray, glm::normalize(b)));
      if (closest < best) {
        best = closest;
        way = sign;
      }
    }
    // A corner (no way into the cloth), or a way within 30 degrees of the border: it would cut off
    // a sliver.
    if (way == 0.0 || best > 0.866) return false;
  }
  const auto ahead = [&](Vec3 x) { return way == 0.0 || way * glm::dot(x - at, crack) > 0.0; };
  Line line(n0, cloth.spacing);
  for (std::size_t p = 0; p < n0; ++p) line.place(p, glm::dot(rest.restPosition(p) - at, pull));
  line.onCut[v] = 1;
  for (const std::uint32_t t : fan) {
    for (int k = 0; k < 3; ++k) {
      const ParticleIndex p = rest.triangles[t][k];
      if (p != v && line.side[p] == 0 && ahead(rest.restPosition(p))) line.onCut[p] = 1;
    }
  }
  line.counts = [&](ParticleIndex p, ParticleIndex q, Real s) {
    return ahead(glm::mix(rest.restPosition(p), rest.restPosition(q), s));
  };
  const bool before = opening.changed;
  opening.changed = false;
  openAlong(cloth, line, &fan, particleBudget, inserted, opening);
  const bool opened = opening.changed;
  opening.changed = before || opened;
  return opened;
}

// A few sweeps over the stretch and shear links within kRelaxRings of the particles `from`, so the
// flanks of a fresh crack let go of their tension before the next pass decides where it runs on.
// The sweeps turn no triangle over: self-contact never tests two triangles that share a corner, so
// nothing else would stop a sweep folding a thin triangle by a fresh crack flat onto its neighbour
// (a cloth lying on a table then lies through itself there until the next step undoes it). The
// moved corners of a triangle the sweeps turned over (its normal now against the one it had) go
// back to where the sweeps found them, until none is turned.
void relax(Cloth& cloth, const std::vector<ParticleIndex>& from) {
  ClothRest& rest = cloth.rest;
  ParticleState& s = cloth.state;
  const Incidence incidence(rest.triangles, rest.particleCount());
  std::vector<std::uint8_t> inside(rest.particleCount(), 0);
  std::vector<ParticleIndex> ring = from;
  for (const ParticleIndex p : ring) inside[p] = 1;
  for (int r = 0; r < kRelaxRings; ++r) {
    std::vector<ParticleIndex> next;
    for (const ParticleIndex p : ring) {
      for (auto t = incidence.begin(p); t != incidence.end(p); ++t) {
        for (int k = 0; k < 3; ++k) {
          const ParticleIndex q = rest.triangles[*t][k];
          if (!inside[q]) {
            inside[q] = 1;
            next.push_back(q);
          }
        }
      }
    }
    ring = std::move(next);
  }
  // The particles the sweeps may move (both ends of a link with an end inside), and where each is
  // in that list (kNone: not in it).
  constexpr std::uint32_t kNone = UINT32_MAX;
  std::vector<std::uint32_t> slot(rest.particleCount(), kNone);
  std::vector<ParticleIndex> region;
  for (const ConstraintKind kind : {ConstraintKind::stretch, ConstraintKind::shear}) {
    for (const DistanceConstraint& c : rest.of(kind)) {
      if (!inside[c.a] && !inside[c.b]) continue;
      for (const ParticleIndex p : {c.a, c.b}) {
        if (slot[p] != kNone) continue;
        slot[p] = static_cast<std::uint32_t>(region.size());
        region.push_back(p);
      }
    }
  }
  const auto normalOf = [&](const Triangle& t) {
    return glm::cross(s.position[t[1]] - s.position[t[0]], s.position[t[2]] - s.position[t[0]]);
  };
  std::vector<Vec3> start(region.size());
  for (std::size_t k = 0; k < region.size(); ++k) start[k] = s.position[region[k]];
  std::vector<std::uint32_t> touched;  // the triangles with a corner in the region, each once
  for (const ParticleIndex p : region) {
    for (auto t = incidence.begin(p); t != incidence.end(p); ++t) touched.push_back(*t);
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  std::vector<Vec3> normalBefore(touched.size());
  for (std::size_t k = 0; k < touched.size(); ++k) normalBefore[k] = normalOf(rest.triangles[touched[k]]);
  // The links with an end inside, stretch then shear, each kind's by particle pair (pair_order.hpp)
  // as the seed's sweep takes them, whatever order the cloth keeps them in.
  std::vector<DistanceConstraint> links;
  for (const ConstraintKind kind : {ConstraintKind::stretch, ConstraintKind::shear}) {
    const std::vector<DistanceConstraint>& all = rest.of(kind);
    std::vector<std::uint32_t> near;
    for (std::uint32_t k = 0; k < all.size(); ++k) {
      if (inside[all[k].a] || inside[all[k].b]) near.push_back(k);
    }
    sortByPair(near, all);
    for (const std::uint32_t k : near) links.push_back(all[k]);
  }
  for (int sweep = 0; sweep < kRelaxSweeps; ++sweep) {
    for (const DistanceConstraint& c : links) {
      const Real wa = s.inverseMass[c.a], wb = s.inverseMass[c.b];
      if (!(wa + wb > 0.0)) continue;
      const Vec3 d = s.position[c.b] - s.position[c.a];
      const Real length = glm::length(d);
      if (!(length > 0.0)) continue;
      const Vec3 correction = (length - static_cast<Real>(c.restLength)) / (length * (wa + wb)) * d;
      s.position[c.a] += wa * correction;
      s.position[c.b] -= wb * correction;
    }
  }
  // Each round puts back at least one particle (a triangle whose corners are all back is as it
  // was, not turned), so this ends.
  for (bool turned = true; turned;) {
    turned = false;
    for (std::size_t k = 0; k < touched.size(); ++k) {
      const Vec3 before = normalBefore[k];
      const Triangle& t = rest.triangles[touched[k]];
      if (!(glm::dot(before, before) > 0.0) || glm::dot(normalOf(t), before) > 0.0) continue;
      for (int corner = 0; corner < 3; ++corner) {
        const ParticleIndex p = t[corner];
        if (slot[p] == kNone || s.position[p] == start[slot[p]]) continue;
        s.position[p] = start[slot[p]];
        turned = true;
      }
    }
  }
}

}  // namespace

bool tear(Cloth& cloth, Real threshold, std::size_t particleBudget, std::vector<ParticleSplit>& splits,
          std::vector<ParticleInsert>& inserted) {
  bool changed = false;
  // A link no triangle witnesses (a chain) breaks alone in its piece: the most strained one, which
  // lets the rest go. Where links are strained alike (a chain pulled evenly), which of them crosses
  // the threshold first is rounding, and breaking them all would shatter the chain.
  {
    const ParticleState& s = cloth.state;
    const auto& stretch = cloth.rest.of(ConstraintKind::stretch);
    std::vector<std::pair<Real, std::uint32_t>> strained;
    for (std::uint32_t j = 0; j < stretch.size(); ++j) {
      const DistanceConstraint& c = stretch[j];
      const Real length = glm::length(s.position[c.b] - s.position[c.a]);
      if (length > threshold * c.restLength) strained.push_back({length / c.restLength, j});
    }
    if (!strained.empty()) {
      build(cloth);
      // The most strained first; between links strained alike, by particle pair (not by where
      // the cloth keeps them).
      const auto pair = [&](std::uint32_t j) {
        return std::pair{std::min(stretch[j].a, stretch[j].b), std::max(stretch[j].a, stretch[j].b)};
      };
      std::sort(strained.begin(), strained.end(), [&](const auto& l, const auto& r) {
        return l.first > r.first || (l.first == r.first && pair(l.second) < pair(r.second));
      });
      Topology& topology = cloth.topology;
      std::vector<std::uint32_t> letGo;  // pieces a free link of has broken
      for (const auto& [ratio, j] : strained) {
        ConstraintTemplate& x =
            topology.templates[topology.source[static_cast<std::size_t>(ConstraintKind::stretch)][j]];
        if (x.link != ConstraintTemplate::Link::free) continue;
        const std::uint32_t piece = stretch[j].a < cloth.piece.size() ? cloth.piece[stretch[j].a] : 0;
        if (std::find(letGo.begin(), letGo.end(), piece) != letGo.end()) continue;
        letGo.push_back(piece);
        x.broken = true;
        ++topology.torn;
        changed = true;
      }
      if (changed) rebuildConstraints(cloth);
    }
  }
  // Triangles: a particle breaks where the stretch of its triangles (their C = F^T F averaged by
  // area) has a principal stretch beyond the threshold, across that principal direction.
  for (int pass = 0; pass < kTearPasses; ++pass) {
    const ClothRest& rest = cloth.rest;
    const std::size_t n = rest.particleCount(), triangles = rest.triangles.size();
    std::vector<Topology::RestFrame>& frames = cloth.topology.restFrames;
    if (frames.size() != triangles) {
      frames.resize(triangles);
      for (std::size_t t = 0; t < triangles; ++t) frames[t] = restFrame(rest, rest.triangles[t]);
    }
    // Each triangle's principal stretch; its whole tensor only where a particle is looked at.
    std::vector<Real> largest(triangles);
    bool any = false;
    for (std::size_t t = 0; t < triangles; ++t) {
      largest[t] = triangleStretch(cloth, rest.triangles[t], frames[t], false).largest;
      if (largest[t] > threshold) any = true;
    }
    const auto tensorOf = [&](std::uint32_t t) { return triangleStretch(cloth, rest.triangles[t], frames[t]).tensor; };
    if (!any) break;
    build(cloth);
    const Incidence incidence(rest.triangles, n);
    // The stretch tensors, averaged by area, of the triangles reached from v through the mesh whose
    // centres lie within kTipReach spacings of it at rest.
    std::vector<std::uint8_t> reached(triangles, 0);
    std::vector<ParticleIndex> front;
    std::vector<std::uint32_t> seen, within;
    const auto stressAround = [&](ParticleIndex v) {
      const Vec3 at = rest.restPosition(v);
      const Real reach = kTipReach * cloth.spacing;
      for (const std::uint32_t t : seen) reached[t] = 0;
      seen.clear();
      within.clear();
      front.assign(1, v);
      while (!front.empty()) {
        const ParticleIndex q = front.back();
        front.pop_back();
        for (auto t = incidence.begin(q); t != incidence.end(q); ++t) {
          if (reached[*t]) continue;
          reached[*t] = 1;
          seen.push_back(*t);
          const Triangle& c = rest.triangles[*t];
          const Vec3 centre = (rest.restPosition(c[0]) + rest.restPosition(c[1]) + rest.restPosition(c[2])) / 3.0;
          if (!(glm::length(centre - at) <= reach)) continue;
          within.push_back(*t);
          for (int k = 0; k < 3; ++k) front.push_back(c[k]);
        }
      }
      std::sort(within.begin(), within.end());  // a sum in one order whatever the walk
      std::array<Real, 6> wide{};
      for (const std::uint32_t t : within) {
        const Real a = triangleArea(rest, rest.triangles[t]);
        const std::array<Real, 6> tensor = tensorOf(t);
        for (std::size_t k = 0; k < 6; ++k) wide[k] += a * tensor[k];
      }
      return wide;
    };
    // The particles of overstretched triangles, as candidates, the most stretched first.
    std::vector<std::uint8_t> candidate(n, 0);
    for (std::size_t t = 0; t < triangles; ++t) {
      if (largest[t] <= threshold) continue;
      for (int k = 0; k < 3; ++k) candidate[rest.triangles[t][k]] = 1;
    }
    // A crack's tip (on a border, its triangles all around it but for the slit) breaks as its most
    // stretched triangle does, across that triangle's pull: stress gathers there. Anywhere else a
    // particle breaks as its triangles do on average, and a crack starts so at most once a step
    // (the most stretched particle), so cracks run on rather than start everywhere at once.
    const auto onBorder = [&](ParticleIndex p) {
      for (auto t = incidence.begin(p); t != incidence.end(p); ++t) {
        const int cp = cornerOf(cloth.rest.triangles[*t], p);
        if (cloth.topology.neighbour[*t][static_cast<std::size_t>(cp)] < 0 ||
            cloth.topology.neighbour[*t][static_cast<std::size_t>((cp + 2) % 3)] < 0)
          return true;
      }
      return false;
    };
    // The angle v's triangles span around it at rest (2 pi inside the cloth).
    const auto fanAngle = [&](ParticleIndex v) {
      Real angle = 0.0;
      for (auto t = incidence.begin(v); t != incidence.end(v); ++t) {
        const Triangle& c = rest.triangles[*t];
        const int cv = cornerOf(c, v);
        const Vec3 e1 = rest.restPosition(c[(cv + 1) % 3]) - rest.restPosition(v);
        const Vec3 e2 = rest.restPosition(c[(cv + 2) % 3]) - rest.restPosition(v);
        if (glm::length(e1) > 0.0 && glm::length(e2) > 0.0)
          angle += std::acos(std::clamp(glm::dot(glm::normalize(e1), glm::normalize(e2)), -1.0, 1.0));
      }
      return angle;
    };
    struct Break {
      Real stretch;
      ParticleIndex particle;
      Vec3 pull;
      bool tip;
    };
    std::vector<Break> breaks;
    for (std::size_t p = 0; p < n; ++p) {
      if (!candidate[p]) continue;
      const auto v = static_cast<ParticleIndex>(p);
      std::array<Real, 6> sum{};
      Real area = 0.0, most = 0.0;
      Vec3 mostPull{0.0};
      for (auto t = incidence.begin(v); t != incidence.end(v); ++t) {
        const Triangle& c = rest.triangles[*t];
        const Real a = triangleArea(rest, c);
        const std::array<Real, 6> tensor = tensorOf(*t);
        for (std::size_t k = 0; k < 6; ++k) sum[k] += a * tensor[k];
        area += a;
        if (largest[*t] > most) {
          most = largest[*t];
          largestEigen(tensor, Vec3{1.0, 0.7, 0.3}, mostPull);
        }
      }
      if (!(area > 0.0)) continue;
      for (Real& e : sum) e /= area;
      Vec3 pull;
      const Real value = std::sqrt(std::max(largestEigen(sum, mostPull, pull), 0.0));
      const bool tip = onBorder(v) && fanAngle(v) > kTipAngle;
      if (tip && most > threshold) {
        // The way a tip runs: across the pull of the triangles within kTipReach spacings of it,
        // which smooths out the tip's own field (it turns sharply around a slit's end) and the
        // lattice's grain.
        largestEigen(stressAround(v), pull, pull);
        breaks.push_back({most, v, pull, true});
      } else if (!tip && value > threshold) {
        breaks.push_back({value, v, pull, false});
      }
    }
    std::sort(breaks.begin(), breaks.end(), [](const Break& l, const Break& r) {
      return l.stretch > r.stretch || (l.stretch == r.stretch && l.particle < r.particle);
    });
    // One break per neighbourhood and pass: the particles of a broken fan wait for the next pass,
    // after the relaxation, so neighbouring breaks do not cut out slivers and islands between them.
    std::vector<std::uint8_t> near(n, 0);
    Opening opening;
    opening.firstNew = cloth.rest.particleCount();
    std::vector<ParticleIndex> broken;
    const std::size_t insertedBefore = inserted.size();
    bool started = pass > 0;
    // The triangles around each particle as they are now: made again after every break (a break
    // splits triangles and puts new ones at the end).
    std::optional<Incidence> now;
    // Where the cloth's crack tips are (at rest), on the mesh as the pass found it: no crack starts
    // within kStartClear spacings of one. Wanted only where one might start (the first pass, and a
    // particle away from tips over the threshold).
    std::vector<Vec3> tips;
    if (!started && std::any_of(breaks.begin(), breaks.end(), [](const Break& b) { return !b.tip; })) {
      for (std::size_t p = 0; p < n; ++p) {
        const auto v = static_cast<ParticleIndex>(p);
        if (onBorder(v) && fanAngle(v) > kTipAngle) tips.push_back(rest.restPosition(v));
      }
    }
    const auto nearATip = [&](ParticleIndex p) {
      const Vec3 x = rest.restPosition(p);
      for (const Vec3& t : tips) {
        if (glm::length(t - x) < kStartClear * cloth.spacing) return true;
      }
      return false;
    };
    for (const Break& b : breaks) {
      if (near[b.particle] || (!b.tip && started)) continue;
      if (!b.tip && nearATip(b.particle)) continue;
      if (!now) now.emplace(cloth.rest.triangles, cloth.rest.particleCount());
      if (!breakAt(cloth, b.particle, b.pull, *now, particleBudget, inserted, opening)) continue;
      if (!b.tip) started = true;
      broken.push_back(b.particle);
      // Its fan's particles, and those of every triangle around them, wait for the next pass.
      now.emplace(cloth.rest.triangles, cloth.rest.particleCount());
      for (auto t = now->begin(b.particle); t != now->end(b.particle); ++t) {
        for (int k = 0; k < 3; ++k) {
          const ParticleIndex q = cloth.rest.triangles[*t][k];
          for (auto u = now->begin(q); u != now->end(q); ++u) {
            for (int e = 0; e < 3; ++e) {
              if (cloth.rest.triangles[*u][e] < n) near[cloth.rest.triangles[*u][e]] = 1;
            }
          }
        }
      }
    }
    if (!opening.changed) break;
    finishOpening(cloth, opening, particleBudget, splits);
    changed = true;
    for (std::size_t k = insertedBefore; k < inserted.size(); ++k) broken.push_back(inserted[k].particle);
    relax(cloth, broken);
  }
  return changed;
}

std::vector<std::uint32_t> pieces(const ClothRest& rest, std::uint32_t& count) {
  const std::size_t n = rest.particleCount();
  std::vector<std::uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  const auto join = [&](std::uint32_t x, std::uint32_t y) {
    x = find(x);
    y = find(y);
    if (x != y) parent[std::max(x, y)] = std::min(x, y);
  };
  for (const Triangle& t : rest.triangles) {
    join(t[0], t[1]);
    join(t[1], t[2]);
  }
  for (const auto& list : rest.constraints) {
    for (const DistanceConstraint& c : list) join(c.a, c.b);
  }
  std::vector<std::uint32_t> label(n, 0);
  std::vector<std::uint32_t> rootLabel(n, UINT32_MAX);
  count = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t root = find(i);
    if (rootLabel[root] == UINT32_MAX) rootLabel[root] = count++;
    label[i] = rootLabel[root];
  }
  if (count <= 1) {
    count = 1;  // (a cloth of no particles is one piece too)
    return {};
  }
  return label;
}

}  // namespace drape::sim::topology
