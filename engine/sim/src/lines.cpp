#include "lines.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <type_traits>

#include <glm/geometric.hpp>

#include "position_model.hpp"

namespace drape::sim::lines {

namespace {

constexpr int kNewtonSteps = 2;

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// Solves G lines of n particles each in place, interleaved: line g has particles p[g][0..n) and
// links 0..n-2. Each line's arithmetic is the same whatever G is; interleaving only lets the core
// overlap the lines' chains of divisions (Thomas' recurrence is serial within a line).
// Scratch arrays hold (n - 1) * G entries, link k of line g at k * G + g.
template <std::size_t G>
void solveLines(ParticleState& s, const std::array<const ParticleIndex*, G>& p, const std::array<const Real*, G>& rest,
                const std::array<Real*, G>& lambda, const std::array<Real*, G>& tensionSum, std::size_t n,
                Real stiffness, Real alphaTilde, Vec3* normal, Real* upper, Real* solution) {
  const std::size_t links = n - 1;
  Vec3* x = s.position.data();
  const Real* w = s.inverseMass.data();
  // Directions, diagonal (in upper) and right-hand side (in solution). A link whose particles
  // coincide, or that nothing can move, gets the row of the identity and no correction.
  for (std::size_t k = 0; k < links; ++k) {
    for (std::size_t g = 0; g < G; ++g) {
      const std::size_t at = k * G + g;
      const Vec3 d = x[p[g][k + 1]] - x[p[g][k]];
      const Real length2 = glm::dot(d, d);
      const Real diagonal = w[p[g][k]] + w[p[g][k + 1]] + alphaTilde;
      if (length2 > 1e-20 && diagonal > 0.0) {
        const Real length = std::sqrt(length2);
        normal[at] = d * (1.0 / length);
        upper[at] = diagonal;
        solution[at] = -(length - rest[g][k]) - (lambda[g] ? alphaTilde * lambda[g][k] : 0.0);
      } else {
        normal[at] = Vec3{0.0};
        upper[at] = 1.0;
        solution[at] = 0.0;
      }
    }
  }
  // Thomas' algorithm. Row k couples to link k - 1 by -w_k (n_{k-1} . n_k), to link k + 1 by
  // -w_{k+1} (n_k . n_{k+1}); upper[k] becomes the eliminated upper entry, solution[k] the
  // eliminated right-hand side.
  // The matrix is symmetric: row k's coupling to link k + 1 is row k + 1's to link k.
  std::array<Real, G> previousUpper{}, previousSolution{}, previousCoupling{};
  for (std::size_t k = 0; k < links; ++k) {
    for (std::size_t g = 0; g < G; ++g) {
      const std::size_t at = k * G + g;
      const Real lower = previousCoupling[g];
      const Real diagonal = upper[at];
      Real pivot = diagonal - lower * previousUpper[g];
      // Only a particle caught between two immovable ones on a straight line makes the system
      // singular; that link is then corrected as if alone.
      if (!(pivot > 1e-9 * diagonal)) pivot = diagonal;
      const Real inverse = 1.0 / pivot;
      const Real coupling = k + 1 < links ? -w[p[g][k + 1]] * glm::dot(normal[at], normal[at + G]) : 0.0;
      previousCoupling[g] = coupling;
      upper[at] = coupling * inverse;
      solution[at] = (solution[at] - lower * previousSolution[g]) * inverse;
      previousUpper[g] = upper[at];
      previousSolution[g] = solution[at];
    }
  }
  for (std::size_t k = links - 1; k-- > 0;) {
    for (std::size_t g = 0; g < G; ++g) solution[k * G + g] -= upper[k * G + g] * solution[(k + 1) * G + g];
  }
  for (std::size_t k = 0; k < links; ++k) {
    for (std::size_t g = 0; g < G; ++g) {
      const std::size_t at = k * G + g;
      const Real dl = solution[at] * stiffness;
      if (lambda[g]) lambda[g][k] += dl;
      if (tensionSum[g]) tensionSum[g][k] += dl;
      const Vec3 push = normal[at] * dl;
      x[p[g][k]] -= push * w[p[g][k]];
      x[p[g][k + 1]] += push * w[p[g][k + 1]];
    }
  }
}

// A symmetric 3 x 3 matrix.
struct Sym3 {
  Real xx = 0.0, yy = 0.0, zz = 0.0, xy = 0.0, xz = 0.0, yz = 0.0;
  Vec3 operator*(Vec3 u) const {
    return {xx * u.x + xy * u.y + xz * u.z, xy * u.x + yy * u.y + yz * u.z, xz * u.x + yz * u.y + zz * u.z};
  }
  Sym3 operator+(const Sym3& o) const { return {xx + o.xx, yy + o.yy, zz + o.zz, xy + o.xy, xz + o.xz, yz + o.yz}; }
  Sym3 operator*(Real a) const { return {xx * a, yy * a, zz * a, xy * a, xz * a, yz * a}; }
};
Sym3 diagonal(Real a) { return {a, a, a, 0.0, 0.0, 0.0}; }
Sym3 outer(Vec3 u) { return {u.x * u.x, u.y * u.y, u.z * u.z, u.x * u.y, u.x * u.z, u.y * u.z}; }
// u v^T + v u^T
Sym3 outer(Vec3 u, Vec3 v) {
  return {2.0 * u.x * v.x,       2.0 * u.y * v.y,       2.0 * u.z * v.z,
          u.x * v.y + u.y * v.x, u.x * v.z + u.z * v.x, u.y * v.z + u.z * v.y};
}
Sym3 inverse(const Sym3& a) {
  const Real cxx = a.yy * a.zz - a.yz * a.yz, cxy = a.xz * a.yz - a.xy * a.zz, cxz = a.xy * a.yz - a.xz * a.yy;
  const Real inv = 1.0 / (a.xx * cxx + a.xy * cxy + a.xz * cxz);
  return {cxx * inv, (a.xx * a.zz - a.xz * a.xz) * inv, (a.xx * a.yy - a.xy * a.xy) * inv, cxy * inv,
          cxz * inv, (a.xy * a.xz - a.xx * a.yz) * inv};
}

// One full Newton step of a line's projection from where its particles are now, geometric
// stiffness included: with dx the particles' moves and l the links' multipliers,
//   K dx - J^T l = 0,   J dx + alpha~ l = -(C + alpha~ lambda),
//   K = M + sum_k G_k (on link k's two particles: [G, -G; -G, G]), G_k = g_k (I - n_k n_k^T),
// g_k = the link's tension (times h^2, from the last substep) over its length. Without G this is
// the tridiagonal solve above; with it a particle's sideways move drags its neighbours, as a taut
// string's does. The unknowns are eliminated in the order x_0, x_1, l_0, x_2, l_1, ...: a front of
// one particle and one link (a 4 x 4 block, its 3 x 3 part inverted), so a pinned particle (which
// does not move: its unknowns drop out) never leaves a link's multiplier without a pivot.
template <std::size_t G>
void solveStiffLines(ParticleState& s, const std::array<const ParticleIndex*, G>& p,
                     const std::array<const Real*, G>& rest, const std::array<Real*, G>& lambda,
                     const std::array<const Real*, G>& tension, const std::array<Real*, G>& tensionSum, std::size_t n,
                     Real stiffness, Real alphaTilde, SolverScratch::StiffRow* rows) {
  Vec3* x = s.position.data();
  const Real* w = s.inverseMass.data();
  const Real* m = s.mass.data();
  const std::size_t links = n - 1;
  // Row of particle (and link) k of line g.
  const auto at = [&](std::size_t k, std::size_t g) -> SolverScratch::StiffRow& { return rows[k * G + g]; };
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t g = 0; g < G; ++g) {
      SolverScratch::StiffRow& r = at(k, g);
      r.live = false;
      r.n = Vec3{0.0};
      r.g = r.rhs = 0.0;
      if (k == links) continue;
      const Vec3 d = x[p[g][k + 1]] - x[p[g][k]];
      const Real length2 = glm::dot(d, d);
      if (!(length2 > 1e-20 && w[p[g][k]] + w[p[g][k + 1]] + alphaTilde > 0.0)) continue;
      const Real length = std::sqrt(length2);
      r.live = true;
      r.n = d * (1.0 / length);
      r.rhs = (length - rest[g][k]) + (lambda[g] ? alphaTilde * lambda[g][k] : 0.0);
      r.g = std::max(-tension[g][k], 0.0) / length;  // pulled links only: a pushed one would make K indefinite
    }
  }
  // G_k u, and G_k as a matrix.
  const auto pull = [](const SolverScratch::StiffRow& link, Vec3 u) {
    return (u - link.n * glm::dot(link.n, u)) * link.g;
  };
  const auto geometric = [](const SolverScratch::StiffRow& link) {
    return (diagonal(1.0) + outer(link.n) * -1.0) * link.g;
  };
  const auto load = [](const SolverScratch::StiffRow& r) {
    return Sym3{r.inverse[0], r.inverse[1], r.inverse[2], r.inverse[3], r.inverse[4], r.inverse[5]};
  };
  const auto store = [](SolverScratch::StiffRow& r, const Sym3& a) {
    r.inverse = {a.xx, a.yy, a.zz, a.xy, a.xz, a.yz};
  };

  // Forward. P is the last node's (S^-1)_xx, zx its (S^-1 y)_x: what it passes on through the link.
  std::array<Sym3, G> P;
  std::array<Vec3, G> zx;
  for (std::size_t g = 0; g < G; ++g) {
    SolverScratch::StiffRow& r = at(0, g);
    P[g] = w[p[g][0]] > 0.0 ? inverse(diagonal(m[p[g][0]]) + geometric(r)) : Sym3{};
    zx[g] = Vec3{0.0};
    store(r, P[g]);
    r.v = r.b = r.yx = Vec3{0.0};
    r.schur = 1.0;
    r.yl = 0.0;
  }
  for (std::size_t j = 1; j < n; ++j) {
    for (std::size_t g = 0; g < G; ++g) {
      const SolverScratch::StiffRow& link = at(j - 1, g);  // joins particle j - 1 to j
      SolverScratch::StiffRow& r = at(j, g);
      const Vec3 Pn = P[g] * link.n;
      const Real nPn = glm::dot(link.n, Pn);
      r.b = pull(link, Pn) - link.n;
      const Real c = link.live ? -alphaTilde - nPn : 1.0;
      r.yx = pull(link, zx[g]);
      r.yl = link.live ? link.rhs - glm::dot(link.n, zx[g]) : 0.0;
      Sym3 inverseA;
      if (w[p[g][j]] > 0.0) {
        // A = m I + G_{j-1} + G_j - G_{j-1} P G_{j-1}
        Sym3 A = diagonal(m[p[g][j]]);
        if (link.g > 0.0) {
          A = A + geometric(link) + (P[g] + outer(link.n, Pn) * -1.0 + outer(link.n) * nPn) * (-link.g * link.g);
        }
        if (r.g > 0.0) A = A + geometric(r);
        inverseA = inverse(A);
        r.v = inverseA * r.b;
        r.schur = c - glm::dot(r.b, r.v);
      } else {
        r.v = Vec3{0.0};
        r.schur = c;
      }
      store(r, inverseA);
      // Both particles held: the link cannot be corrected.
      if (!(std::abs(r.schur) > 0.0)) {
        r.schur = 1.0;
        r.yl = 0.0;
      }
      r.schur = 1.0 / r.schur;  // from here on, its inverse
      const Vec3 t = inverseA * r.yx;
      const Real zl = (r.yl - glm::dot(r.b, t)) * r.schur;
      zx[g] = t - r.v * zl;
      P[g] = inverseA + outer(r.v) * r.schur;
    }
  }

  // Back: particle j's move and link j - 1's multiplier, from node j + 1's.
  std::array<Vec3, G> ux;
  std::array<Real, G> ul{};
  ux.fill(Vec3{0.0});
  for (std::size_t j = n; j-- > 0;) {
    for (std::size_t g = 0; g < G; ++g) {
      const SolverScratch::StiffRow& r = at(j, g);
      Vec3 px = r.yx;
      if (j + 1 < n) px += pull(r, ux[g]) - r.n * ul[g];  // minus link j's coupling to node j + 1
      const Vec3 t = load(r) * px;
      ul[g] = j > 0 ? (r.yl - glm::dot(r.b, t)) * r.schur : 0.0;
      ux[g] = t - r.v * ul[g];
      if (w[p[g][j]] > 0.0) x[p[g][j]] += ux[g] * stiffness;
      if (j > 0 && at(j - 1, g).live) {
        if (lambda[g]) lambda[g][j - 1] += ul[g] * stiffness;
        tensionSum[g][j - 1] += ul[g] * stiffness;
      }
    }
  }
}

// Lines [first, last) of a family, four at a time where four in a row are equally long (G = 4),
// else one (G = 1): solve(std::integral_constant<std::size_t, G>, particles, rests, lambdas,
// offsets, n), each array holding G lines' pointers (lambdas null without XPBD) and offsets their
// starts.
template <class Solve>
void inGroups(SolverScratch::LineFamily& lines, std::size_t first, std::size_t last, bool xpbd, Solve&& solve) {
  constexpr std::size_t G = 4;
  const auto length = [&](std::size_t l) { return lines.start[l + 1] - lines.start[l]; };
  const auto gather = [&]<std::size_t N>(std::integral_constant<std::size_t, N> size, std::size_t l, std::size_t n) {
    std::array<const ParticleIndex*, N> p{};
    std::array<const Real*, N> rest{};
    std::array<Real*, N> lambda{};
    std::array<std::size_t, N> offset{};
    for (std::size_t g = 0; g < N; ++g) {
      offset[g] = lines.start[l + g];
      p[g] = lines.particle.data() + offset[g];
      rest[g] = lines.rest.data() + offset[g];
      lambda[g] = xpbd ? lines.lambda.data() + offset[g] : nullptr;
    }
    solve(size, p, rest, lambda, offset, n);
  };
  for (std::size_t l = first; l < last;) {
    const std::size_t n = length(l);
    bool group = l + G <= last && n >= 2;
    for (std::size_t g = 1; group && g < G; ++g) group = length(l + g) == n;
    if (group) {
      gather(std::integral_constant<std::size_t, G>{}, l, n);
      l += G;
      continue;
    }
    if (n >= 2) gather(std::integral_constant<std::size_t, 1>{}, l, n);
    ++l;
  }
}

}  // namespace

void build(const Cloth& cloth, SolverScratch& scratch, int threads) {
  const std::vector<DistanceConstraint>& stretch = cloth.rest.of(ConstraintKind::stretch);
  const std::size_t n = cloth.rest.restPositions.size();
  scratch.looseStretch.clear();
  std::size_t longest = 0;
  for (int family = 0; family < 2; ++family) {
    SolverScratch::LineFamily& lines = scratch.lines[static_cast<std::size_t>(family)];
    lines = {};
    std::vector<std::uint8_t> degree(n, 0);
    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    std::vector<std::array<std::int64_t, 2>> next(n, {-1, -1});  // the constraints at each particle
    for (std::uint32_t k = 0; k < stretch.size(); ++k) {
      const DistanceConstraint& c = stretch[k];
      const Vec3 d = glm::abs(cloth.rest.restPositions[c.b] - cloth.rest.restPositions[c.a]);
      const bool alongX = d.x >= std::max(d.y, d.z);
      if (alongX != (family == 0)) continue;
      const std::uint32_t ra = findRoot(parent, c.a), rb = findRoot(parent, c.b);
      if (degree[c.a] >= 2 || degree[c.b] >= 2 || ra == rb) {
        scratch.looseStretch.push_back(k);
        continue;
      }
      parent[ra] = rb;
      next[c.a][degree[c.a]++] = k;
      next[c.b][degree[c.b]++] = k;
    }
    // Walk each line from one of its ends.
    std::vector<std::uint8_t> done(n, 0);
    for (std::size_t start = 0; start < n; ++start) {
      if (degree[start] != 1 || done[start]) continue;
      lines.start.push_back(static_cast<std::uint32_t>(lines.particle.size()));
      std::size_t at = start;
      std::int64_t from = -1;
      std::size_t length = 0;
      while (true) {
        done[at] = 1;
        lines.particle.push_back(static_cast<ParticleIndex>(at));
        ++length;
        std::int64_t link = -1;
        for (std::int64_t candidate : next[at]) {
          if (candidate >= 0 && candidate != from) link = candidate;
        }
        if (link < 0) {
          lines.rest.push_back(0.0);
          break;
        }
        const DistanceConstraint& c = stretch[static_cast<std::size_t>(link)];
        lines.rest.push_back(c.restLength);
        at = c.a == at ? c.b : c.a;
        from = link;
      }
      longest = std::max(longest, length);
    }
    lines.start.push_back(static_cast<std::uint32_t>(lines.particle.size()));
    lines.lambda.clear();  // sized by the XPBD solve, which alone uses it
  }
  scratch.lineStride = longest * 4;  // four lines interleaved
  const std::size_t slices = scratch.lineStride * static_cast<std::size_t>(std::max(threads, 1));
  scratch.lineNormal.assign(slices, Vec3{0.0});
  scratch.lineUpper.assign(slices, 0.0);
  scratch.lineSolution.assign(slices, 0.0);
}

void solve(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, bool geometricStiffness,
           Workers& workers, Real* looseLambda) {
  ParticleState& s = cloth.state;
  if (geometricStiffness) {
    const std::size_t rows = scratch.lineStride * static_cast<std::size_t>(workers.threads());
    if (scratch.lineStiff.size() < rows) scratch.lineStiff.resize(rows);
    for (SolverScratch::LineFamily& lines : scratch.lines) {
      lines.tension.resize(lines.rest.size(), 0.0);
      lines.tensionSum.resize(lines.rest.size(), 0.0);
    }
  }
  // Two Newton steps: rows, columns, rows, columns. One leaves enough of the linearisation's error
  // that, where the cloth moves fast (a whipping hem), it grows from substep to substep; after two
  // it does not (docs/performance.md). With geometric stiffness the first step is the full Newton
  // step (which keeps kinks from growing) and the second the tridiagonal one (which only refines the
  // lengths): taking both full costs 1.7 times as much on hang2 for no stiffer a cloth.
  for (int step = 0; step < kNewtonSteps; ++step) {
    for (SolverScratch::LineFamily& lines : scratch.lines) {
      if (lines.start.size() < 2) continue;
      const std::size_t count = lines.start.size() - 1;
      // Shared out only where each thread gets a few thousand links: below that, waking a helper
      // costs more than it saves.
      const std::size_t perLine = std::max<std::size_t>(lines.particle.size() / count, 1);
      workers.run(
          count,
          [&](std::size_t first, std::size_t last, int thread) {
            const Real alpha = xpbd ? alphaTilde : 0.0;
            const std::size_t slice = scratch.lineStride * static_cast<std::size_t>(thread);
            inGroups(lines, first, last, xpbd,
                     [&]<std::size_t G>(std::integral_constant<std::size_t, G>, const auto& p, const auto& rest,
                                        const auto& lambda, const auto& offset, std::size_t n) {
                       // With geometric stiffness every solve adds its multipliers to the tension sums.
                       std::array<const Real*, G> tension{};
                       std::array<Real*, G> tensionSum{};
                       for (std::size_t g = 0; geometricStiffness && g < G; ++g) {
                         tension[g] = lines.tension.data() + offset[g];
                         tensionSum[g] = lines.tensionSum.data() + offset[g];
                       }
                       if (geometricStiffness && step == 0) {
                         solveStiffLines<G>(s, p, rest, lambda, tension, tensionSum, n, stiffness, alpha,
                                            scratch.lineStiff.data() + slice);
                       } else {
                         solveLines<G>(s, p, rest, lambda, tensionSum, n, stiffness, alpha,
                                       scratch.lineNormal.data() + slice, scratch.lineUpper.data() + slice,
                                       scratch.lineSolution.data() + slice);
                       }
                     });
          },
          std::max<std::size_t>(2048 / perLine, 1));
    }
  }
  const std::vector<DistanceConstraint>& stretch = cloth.rest.of(ConstraintKind::stretch);
  for (const std::uint32_t k : scratch.looseStretch) {
    if (xpbd && looseLambda) {
      position::projectCompliant(s.position, s.inverseMass, stretch[k], alphaTilde, looseLambda[k]);
    } else {
      position::projectDistance(s.position, s.inverseMass, stretch[k], stiffness);
    }
  }
}

}  // namespace drape::sim::lines
