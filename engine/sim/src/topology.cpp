#include "topology.hpp"

#include <algorithm>
#include <numeric>
#include <tuple>

#include <glm/geometric.hpp>

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

Vec3 restCentroid(const ClothRest& rest, const Triangle& t) {
  return (rest.restPosition(t[0]) + rest.restPosition(t[1]) + rest.restPosition(t[2])) / 3.0;
}

void addTemplates(Topology& topology, const ClothRest& rest, const Incidence& incidence, ConstraintKind kind,
                  const DistanceConstraint& c) {
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
  if (topology.templates.size() > first) return;
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
  std::sort(made.begin(), made.end(), [](const Made& l, const Made& r) {
    return std::tie(l.kind, l.a, l.b, l.from) < std::tie(r.kind, r.a, r.b, r.from);
  });
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
// that is exact. A share of all or more of it is cut to half.
MassReal takeShare(MassReal& left, Real wanted) {
  MassReal share = static_cast<MassReal>(wanted);
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

}  // namespace

void build(Cloth& cloth) {
  Topology& topology = cloth.topology;
  if (topology.built) return;
  const ClothRest& rest = cloth.rest;
  const auto& triangles = rest.triangles;
  topology.neighbour.assign(triangles.size(), {-1, -1, -1});
  topology.triangleArea.resize(triangles.size());
  // Pair up the triangles on each edge; an edge of three or more triangles joins none of them.
  struct EdgeUse {
    std::uint64_t key;
    std::uint32_t triangle;
    int edge;
  };
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
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& l, const EdgeUse& r) {
    return std::tie(l.key, l.triangle) < std::tie(r.key, r.triangle);
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
  const Incidence incidence(triangles, rest.particleCount());
  topology.templates.clear();
  for (ConstraintKind kind : kConstraintKinds) {
    auto& source = topology.source[static_cast<std::size_t>(kind)];
    source.clear();
    for (const DistanceConstraint& c : rest.of(kind)) {
      source.push_back(static_cast<std::uint32_t>(topology.templates.size()));
      addTemplates(topology, rest, incidence, kind, c);
    }
  }
  topology.built = true;
}

bool tear(Cloth& cloth, Real threshold, std::size_t particleBudget, std::vector<ParticleSplit>& splits) {
  const ParticleState& s = cloth.state;
  const auto& stretch = cloth.rest.of(ConstraintKind::stretch);
  std::vector<std::pair<Real, std::uint32_t>> strained;
  for (std::uint32_t j = 0; j < stretch.size(); ++j) {
    const DistanceConstraint& c = stretch[j];
    const Real length = glm::length(s.position[c.b] - s.position[c.a]);
    if (length > threshold * c.restLength) strained.push_back({length / c.restLength, j});
  }
  if (strained.empty()) return false;
  build(cloth);
  // The most strained first: they decide where the crack runs.
  std::sort(strained.begin(), strained.end(), [](const auto& l, const auto& r) {
    return l.first > r.first || (l.first == r.first && l.second < r.second);
  });
  Topology& topology = cloth.topology;
  const ClothRest& rest = cloth.rest;
  const Incidence incidence(rest.triangles, rest.particleCount());
  std::vector<ParticleIndex> touched;
  bool changed = false;
  // Severs the joined edges at v that separate triangles ahead of v along `pull` from those behind.
  const auto severAround = [&](ParticleIndex v, Vec3 pull) {
    bool severed = false;
    const auto ahead = [&](std::uint32_t t) {
      return glm::dot(restCentroid(rest, rest.triangles[t]) - rest.restPosition(v), pull) > 0.0;
    };
    for (auto t = incidence.begin(v); t != incidence.end(v); ++t) {
      const int cv = cornerOf(rest.triangles[*t], v);
      for (const int edge : {cv, (cv + 2) % 3}) {
        const std::int32_t other = topology.neighbour[*t][static_cast<std::size_t>(edge)];
        if (other < 0 || ahead(*t) == ahead(static_cast<std::uint32_t>(other))) continue;
        sever(topology, *t, edge);
        touched.push_back(rest.triangles[*t][edge]);
        touched.push_back(rest.triangles[*t][(edge + 1) % 3]);
        severed = true;
      }
    }
    return severed;
  };
  // One crack step per neighbourhood and pass: a constraint next to particles this pass already
  // severed around waits for the next pass (and its own strain then), so neighbouring cracks do not
  // cut out slivers and islands between them.
  std::vector<std::uint8_t> near(rest.particleCount(), 0);
  // A free link (no triangle: a chain) breaks alone in its piece: the most strained one, which lets
  // the rest go. Where links are strained alike (a chain pulled evenly), which of them crosses the
  // threshold first is rounding, and breaking them all would shatter the chain.
  std::vector<std::uint32_t> letGo;  // pieces a free link of has broken this pass
  for (const auto& [ratio, j] : strained) {
    ConstraintTemplate& x = topology.templates[topology.source[static_cast<std::size_t>(ConstraintKind::stretch)][j]];
    if (x.link == ConstraintTemplate::Link::free) {
      const std::uint32_t piece = stretch[j].a < cloth.piece.size() ? cloth.piece[stretch[j].a] : 0;
      if (std::find(letGo.begin(), letGo.end(), piece) != letGo.end()) continue;
      letGo.push_back(piece);
      x.broken = true;
      ++topology.torn;
      changed = true;
      continue;
    }
    const DistanceConstraint& c = stretch[j];
    if (near[c.a] || near[c.b]) continue;
    const std::size_t before = touched.size();
    const Vec3 pull = rest.restPosition(c.b) - rest.restPosition(c.a);
    if (severAround(c.a, pull) || severAround(c.b, -pull)) changed = true;
    // Mark the triangles around every particle on the new crack.
    for (std::size_t k = before; k < touched.size(); ++k) {
      for (auto t = incidence.begin(touched[k]); t != incidence.end(touched[k]); ++t) {
        for (int corner = 0; corner < 3; ++corner) near[rest.triangles[*t][corner]] = 1;
      }
    }
  }
  if (!changed) return false;
  splitParticles(cloth, std::move(touched), particleBudget, splits);
  rebuildConstraints(cloth);
  return true;
}

bool cut(Cloth& cloth, Vec3 a, Vec3 b, Vec3 depth, std::size_t particleBudget, std::vector<ParticleSplit>& splits) {
  const Real length = glm::length(b - a);
  const Vec3 across = glm::cross(b - a, depth);
  if (!(length > 1e-12) || !(glm::length(across) > 1e-12 * length)) return false;
  const Vec3 along = (b - a) / length;
  const Vec3 normal = glm::normalize(across);
  const ParticleState& s = cloth.state;
  const auto left = [&](ParticleIndex p) { return glm::dot(s.position[p] - a, normal) >= 0.0; };
  const auto within = [&](Vec3 x) {
    const Real u = glm::dot(x - a, along);
    return u >= 0.0 && u <= length;
  };
  build(cloth);
  Topology& topology = cloth.topology;
  const auto& triangles = cloth.rest.triangles;
  std::vector<ParticleIndex> touched;
  bool changed = false;
  // The crack runs along the edges that bound the crossed triangles on the left: such an edge has
  // both ends on the left, and of its two triangles one lies wholly on the left, the other is crossed.
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t other = topology.neighbour[t][static_cast<std::size_t>(k)];
      if (other < static_cast<std::int32_t>(t)) continue;  // none, or seen from the other side
      const Triangle& tri = triangles[t];
      const Triangle& next = triangles[static_cast<std::size_t>(other)];
      const ParticleIndex p = tri[k], q = tri[(k + 1) % 3], r = tri[(k + 2) % 3];
      ParticleIndex rOther = next[0];
      for (int m = 0; m < 3; ++m) {
        if (next[m] != p && next[m] != q) rOther = next[m];
      }
      if (!left(p) || !left(q) || left(r) == left(rOther)) continue;
      const Triangle& crossed = left(r) ? next : tri;
      if (!within((s.position[crossed[0]] + s.position[crossed[1]] + s.position[crossed[2]]) / 3.0)) continue;
      sever(topology, t, k);
      touched.push_back(p);
      touched.push_back(q);
      changed = true;
    }
  }
  for (ConstraintTemplate& x : topology.templates) {
    if (x.link != ConstraintTemplate::Link::free || x.broken) continue;
    const Vec3 xa = s.position[x.t1], xb = s.position[x.t2];
    const Real da = glm::dot(xa - a, normal), db = glm::dot(xb - a, normal);
    if ((da >= 0.0) == (db >= 0.0)) continue;
    if (!within(xa + (xb - xa) * (da / (da - db)))) continue;
    x.broken = true;
    ++topology.torn;
    changed = true;
  }
  if (!changed) return false;
  splitParticles(cloth, std::move(touched), particleBudget, splits);
  rebuildConstraints(cloth);
  return true;
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
