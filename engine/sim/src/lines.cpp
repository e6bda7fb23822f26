#include "lines.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>
#include <type_traits>

#if defined(__AVX__)
#include <immintrin.h>
#elif defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <glm/geometric.hpp>

#include "position_model.hpp"

namespace drape::sim::lines {

namespace {

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
                const std::array<Real*, G>& lambda, const std::array<float*, G>& tensionSum, std::size_t n,
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
      if (tensionSum[g]) tensionSum[g][k] = static_cast<float>(tensionSum[g][k] + dl);
      const Vec3 push = normal[at] * dl;
      x[p[g][k]] -= push * w[p[g][k]];
      x[p[g][k + 1]] += push * w[p[g][k + 1]];
    }
  }
}

// Floats side by side, one line's arithmetic in each: four lines in one instruction (SSE, the
// portable baseline), eight with AVX. The full Newton step runs in single precision: it only has to
// find the direction the second, double-precision step refines (the links' lengths it leaves are
// that step's to correct).
constexpr std::size_t kLanes = SolverScratch::StiffRows::kLanes;
using Lane = float __attribute__((vector_size(4 * kLanes)));
using Lanes = SolverScratch::StiffRows::Lanes;
struct Lane3 {
  Lane x, y, z;
};
struct LaneSym3 {
  Lane xx, yy, zz, xy, xz, yz;
};
Lane load(const Lanes& a) {
  Lane v;
  std::memcpy(&v, a.data(), sizeof v);
  return v;
}
void keep(Lanes& a, Lane v) { std::memcpy(a.data(), &v, sizeof v); }
Lane3 load(const std::array<Lanes, 3>& a) { return {load(a[0]), load(a[1]), load(a[2])}; }
void keep(std::array<Lanes, 3>& a, const Lane3& v) {
  keep(a[0], v.x);
  keep(a[1], v.y);
  keep(a[2], v.z);
}
LaneSym3 load(const std::array<Lanes, 6>& a) {
  return {load(a[0]), load(a[1]), load(a[2]), load(a[3]), load(a[4]), load(a[5])};
}
void keep(std::array<Lanes, 6>& a, const LaneSym3& m) {
  keep(a[0], m.xx);
  keep(a[1], m.yy);
  keep(a[2], m.zz);
  keep(a[3], m.xy);
  keep(a[4], m.xz);
  keep(a[5], m.yz);
}
Lane3 operator+(const Lane3& a, const Lane3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Lane3 operator-(const Lane3& a, const Lane3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Lane3 operator*(const Lane3& a, Lane s) { return {a.x * s, a.y * s, a.z * s}; }
Lane dot(const Lane3& a, const Lane3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
using Mask = std::int32_t __attribute__((vector_size(4 * kLanes)));
// 1 in the lanes a comparison holds in, else 0.
Lane ones(Mask holds) {
  const Lane one = Lane{} + 1.0f;
  return std::bit_cast<Lane>(holds & std::bit_cast<Mask>(one));
}
// a where the comparison holds, else b.
Lane select(Mask holds, Lane a, Lane b) {
  return std::bit_cast<Lane>((holds & std::bit_cast<Mask>(a)) | (~holds & std::bit_cast<Mask>(b)));
}
Lane squareRoot(Lane a) {
#if defined(__AVX__)
  return _mm256_sqrt_ps(a);
#elif defined(__SSE__)
  return _mm_sqrt_ps(a);
#else
  for (std::size_t lane = 0; lane < kLanes; ++lane) a[lane] = std::sqrt(a[lane]);
  return a;
#endif
}
Lane3 operator*(const LaneSym3& m, const Lane3& u) {
  return {m.xx * u.x + m.xy * u.y + m.xz * u.z, m.xy * u.x + m.yy * u.y + m.yz * u.z,
          m.xz * u.x + m.yz * u.y + m.zz * u.z};
}
LaneSym3 operator+(const LaneSym3& a, const LaneSym3& b) {
  return {a.xx + b.xx, a.yy + b.yy, a.zz + b.zz, a.xy + b.xy, a.xz + b.xz, a.yz + b.yz};
}
LaneSym3 operator*(const LaneSym3& a, Lane s) { return {a.xx * s, a.yy * s, a.zz * s, a.xy * s, a.xz * s, a.yz * s}; }
// s (I - u u^T)
LaneSym3 across(const Lane3& u, Lane s) {
  return {(1.0f - u.x * u.x) * s, (1.0f - u.y * u.y) * s, (1.0f - u.z * u.z) * s,
          -u.x * u.y * s,         -u.x * u.z * s,         -u.y * u.z * s};
}
LaneSym3 outer(const Lane3& u) { return {u.x * u.x, u.y * u.y, u.z * u.z, u.x * u.y, u.x * u.z, u.y * u.z}; }
// u v^T + v u^T
LaneSym3 outer(const Lane3& u, const Lane3& v) {
  return {2.0f * u.x * v.x,      2.0f * u.y * v.y,      2.0f * u.z * v.z,
          u.x * v.y + u.y * v.x, u.x * v.z + u.z * v.x, u.y * v.z + u.z * v.y};
}
[[gnu::always_inline]] inline LaneSym3 inverse(const LaneSym3& a) {
  const Lane cxx = a.yy * a.zz - a.yz * a.yz, cxy = a.xz * a.yz - a.xy * a.zz, cxz = a.xy * a.yz - a.xz * a.yy;
  const Lane inv = 1.0f / (a.xx * cxx + a.xy * cxy + a.xz * cxz);
  return {cxx * inv, (a.xx * a.zz - a.xz * a.xz) * inv, (a.xx * a.yy - a.xy * a.xy) * inv, cxy * inv,
          cxz * inv, (a.xy * a.xz - a.xx * a.yz) * inv};
}

// A link as the solve uses it: its direction, geometric stiffness g, value C + alpha~ lambda, and 1
// if the solve corrects it (else 0).
struct Link {
  Lane3 unit;
  Lane pull, rhs, live;
};

// Link j from what solveStiffLines gathered into row j: the difference of its particles (in nx, ny,
// nz), its rest length less alpha~ lambda (rhs), its tension over the unit mass (g) and 1 if
// anything can move it (live). A link with no direction is dead. Keeps in the row what the back
// substitution reads again: the direction and g.
Link normalise(SolverScratch::StiffRows& r) {
  const Lane3 d{load(r.nx), load(r.ny), load(r.nz)};
  const Lane length2 = dot(d, d);
  const Lane live = load(r.live) * ones(length2 > 1e-20f);
  const Lane length = squareRoot(length2 * live + (1.0f - live));  // 1 where dead
  const Lane inverseLength = live / length;
  const Link link{d * inverseLength, load(r.g) * inverseLength, (length - load(r.rhs)) * live, live};
  keep(r.nx, link.unit.x);
  keep(r.ny, link.unit.y);
  keep(r.nz, link.unit.z);
  keep(r.g, link.pull);
  return link;
}

// The elimination of solveStiffLines for the kLanes lanes of rows[0, n), gathered. On return each
// row's yx holds its particle's move and yl its link-before's multiplier.
void solveStiffLanes(SolverScratch::StiffRows* rows, std::size_t n, Lane alphaTilde) {
  using Row = SolverScratch::StiffRows;
  const auto direction = [](const Row& r) { return Lane3{load(r.nx), load(r.ny), load(r.nz)}; };
  const Lane zero{}, one = zero + 1.0f;
  // Forward. P is the last node's (S^-1)_xx, zx its (S^-1 y)_x: what it passes on through the link.
  LaneSym3 P;
  Lane3 zx{zero, zero, zero};
  Link next = normalise(rows[0]);
  LaneSym3 nextAcross = across(next.unit, next.pull);  // G of the link after the node
  {
    Row& r = rows[0];
    const Lane m = load(r.mass);
    const LaneSym3 inverseA = inverse(LaneSym3{m, m, m, zero, zero, zero} + nextAcross) * load(r.moves);
    keep(r.inverse, inverseA);
    P = inverseA;
    keep(r.v, zx);
    keep(r.b, zx);
    keep(r.yx, zx);
    keep(r.schur, one);
    keep(r.yl, zero);
  }
  for (std::size_t j = 1; j < n; ++j) {
    const Link link = next;  // joins particle j - 1 to j
    const LaneSym3 linkAcross = nextAcross;
    Row& r = rows[j];
    next = normalise(r);
    nextAcross = across(next.unit, next.pull);
    const Lane3 unit = link.unit;
    const Lane pull = link.pull, live = link.live;
    const Lane3 Pn = P * unit;
    const Lane nPn = dot(unit, Pn);
    const Lane3 b = (Pn - unit * nPn) * pull - unit;
    const Lane c = live * (-alphaTilde - nPn) + (1.0f - live);  // a dead link: the row of the identity
    const Lane nz = dot(unit, zx);
    const Lane3 yx = (zx - unit * nz) * pull;
    Lane yl = live * (link.rhs - nz);
    // A = m I + G_{j-1} + G_j - G_{j-1} P G_{j-1}
    const Lane m = load(r.mass);
    const LaneSym3 A = LaneSym3{m, m, m, zero, zero, zero} + linkAcross + nextAcross +
                       (P + outer(unit, Pn) * -one + outer(unit) * nPn) * (-pull * pull);
    const LaneSym3 inverseA = inverse(A) * load(r.moves);
    const Lane3 v = inverseA * b;
    Lane schur = c - dot(b, v);
    // Both particles held (or a zero pivot): the link cannot be corrected.
    const Mask correctable = (schur > 0.0f) | (schur < 0.0f);
    schur = select(correctable, schur, one);
    yl = select(correctable, yl, zero);
    schur = 1.0f / schur;
    const Lane3 t = inverseA * yx;
    const Lane zl = (yl - dot(b, t)) * schur;
    zx = t - v * zl;
    P = inverseA + outer(v) * schur;
    keep(r.inverse, inverseA);
    keep(r.v, v);
    keep(r.b, b);
    keep(r.yx, yx);
    keep(r.schur, schur);
    keep(r.yl, yl);
  }

  // Back: particle j's move and link j - 1's multiplier, from node j + 1's.
  Lane3 ux{zero, zero, zero};
  Lane ul = zero;
  for (std::size_t j = n; j-- > 0;) {
    Row& r = rows[j];
    Lane3 px = load(r.yx);
    if (j + 1 < n) {  // minus link j's coupling to node j + 1
      const Lane3 unit = direction(r);
      px = px + (ux - unit * dot(unit, ux)) * load(r.g) - unit * ul;
    }
    const Lane3 t = load(r.inverse) * px;
    ul = j > 0 ? (load(r.yl) - dot(load(r.b), t)) * load(r.schur) : zero;
    ux = t - load(r.v) * ul;
    keep(r.yx, ux);
    keep(r.yl, ul);
  }
}

// One full Newton step of G lines' projections from where their particles are now, geometric
// stiffness included: with dx the particles' moves and l the links' multipliers,
//   K dx - J^T l = 0,   J dx + alpha~ l = -(C + alpha~ lambda),
//   K = M + sum_k G_k (on link k's two particles: [G, -G; -G, G]), G_k = g_k (I - n_k n_k^T),
// g_k = the link's tension (times h^2, from the last substep) over its length (Tournier et al.
// 2015, Andrews et al. 2017). Without G this is solveLines' tridiagonal system; with it a
// particle's sideways move drags its neighbours, as a taut string's does. The unknowns are
// eliminated in the order x_0, x_1, l_0, x_2, l_1, ...: a front of one particle and one link (a
// 3 x 3 inverse and a scalar pivot), so a held particle (whose unknowns drop out) never leaves a
// link's multiplier without a pivot. rows holds n rows; the lines' data is gathered into lanes,
// solved by solveStiffLanes kLanes lines at once, and the moves and multipliers scattered back.
template <std::size_t G>
void solveStiffLines(ParticleState& s, const std::array<const ParticleIndex*, G>& p,
                     const std::array<const Real*, G>& rest, const std::array<Real*, G>& lambda,
                     const std::array<const float*, G>& tension, const std::array<float*, G>& tensionSum, std::size_t n,
                     Real stiffness, Real alphaTilde, SolverScratch::StiffRows* rows) {
  static_assert(G <= kLanes);
  using Row = SolverScratch::StiffRows;
  Vec3* x = s.position.data();
  const Real* w = s.inverseMass.data();
  const Real* mass = s.mass.data();
  const std::size_t links = n - 1;
  // Gathered first: each link's direction, value and geometric stiffness, each particle's mass.
  // Each line's system is solved in units of its first particle's mass (K / s, alpha~ s, l / s,
  // s = that mass), so that single precision holds whatever the cloth weighs.
  std::array<Real, kLanes> unitMass, perUnitMass;
  unitMass.fill(1.0);
  perUnitMass.fill(1.0);
  Lanes alpha{};
  for (std::size_t g = 0; g < G; ++g) {
    unitMass[g] = mass[p[g][0]] > 0.0 ? mass[p[g][0]] : 1.0;
    perUnitMass[g] = 1.0 / unitMass[g];
    alpha[g] = static_cast<float>(alphaTilde * unitMass[g]);
  }
  for (std::size_t k = 0; k < n; ++k) {
    Row& r = rows[k];
    // Each link's difference (in double: the particles' distance from the origin may be a thousand
    // links), rest length, tension, and whether anything can move it; solveStiffLanes makes of them
    // the link's direction, value and geometric stiffness (normalise). Lanes no line fills hold a
    // free particle and no link.
    for (std::size_t g = 0; g < kLanes; ++g) {
      r.mass[g] = g < G ? static_cast<float>(mass[p[g][k]] * perUnitMass[g]) : 1.0f;
      r.moves[g] = g < G && w[p[g][k]] > 0.0 ? 1.0f : 0.0f;
      r.nx[g] = r.ny[g] = r.nz[g] = r.rhs[g] = r.g[g] = r.live[g] = 0.0f;
      if (g >= G || k == links) continue;
      const Vec3 d = x[p[g][k + 1]] - x[p[g][k]];
      r.nx[g] = static_cast<float>(d.x);
      r.ny[g] = static_cast<float>(d.y);
      r.nz[g] = static_cast<float>(d.z);
      // C + alpha~ lambda = length - (rest - alpha~ lambda)
      r.rhs[g] = static_cast<float>(rest[g][k] - (lambda[g] ? alphaTilde * lambda[g][k] : 0.0));
      // Pulled links only: a pushed one would make K indefinite.
      r.g[g] = static_cast<float>(std::max(-static_cast<Real>(tension[g][k]), 0.0) * perUnitMass[g]);
      r.live[g] = w[p[g][k]] + w[p[g][k + 1]] + alphaTilde > 0.0 ? 1.0f : 0.0f;
    }
  }
  // A held particle or a dead link is masked, not branched on.
  solveStiffLanes(rows, n, load(alpha));
  // A dead link's multiplier comes out 0 and is added all the same; a held particle is not touched
  // (its move is 0 too, but it must stay put even if something upstream went non-finite).
  std::array<Real, kLanes> multiplierScale{};
  for (std::size_t g = 0; g < G; ++g) multiplierScale[g] = unitMass[g] * stiffness;
  for (std::size_t j = 0; j < n; ++j) {
    const Row& r = rows[j];
    for (std::size_t g = 0; g < G; ++g) {
      if (r.moves[g] != 0.0f) x[p[g][j]] += Vec3{r.yx[0][g], r.yx[1][g], r.yx[2][g]} * stiffness;
      if (j == 0) continue;
      const Real multiplier = static_cast<Real>(r.yl[g]) * multiplierScale[g];
      if (lambda[g]) lambda[g][j - 1] += multiplier;
      tensionSum[g][j - 1] = static_cast<float>(tensionSum[g][j - 1] + multiplier);
    }
  }
}

// The lines line[0, count) of a family, W at a time where W in a row are equally long (G = W),
// else one (G = 1): solve(std::integral_constant<std::size_t, G>, particles, rests,
// lambdas, offsets, n), each array holding G lines' pointers (lambdas null without XPBD) and
// offsets their starts. A line's arithmetic does not depend on which lines it is solved beside.
template <std::size_t W, class Solve>
void inGroups(SolverScratch::LineFamily& lines, const std::uint32_t* line, std::size_t count, bool xpbd,
              Solve&& solve) {
  constexpr std::size_t G = W;
  const auto length = [&](std::size_t i) { return lines.start[line[i] + 1] - lines.start[line[i]]; };
  const auto gather = [&]<std::size_t N>(std::integral_constant<std::size_t, N> size, std::size_t i, std::size_t n) {
    std::array<const ParticleIndex*, N> p{};
    std::array<const Real*, N> rest{};
    std::array<Real*, N> lambda{};
    std::array<std::size_t, N> offset{};
    for (std::size_t g = 0; g < N; ++g) {
      offset[g] = lines.start[line[i + g]];
      p[g] = lines.particle.data() + offset[g];
      rest[g] = lines.rest.data() + offset[g];
      lambda[g] = xpbd ? lines.lambda.data() + offset[g] : nullptr;
    }
    solve(size, p, rest, lambda, offset, n);
  };
  for (std::size_t i = 0; i < count;) {
    const std::size_t n = length(i);
    bool group = i + G <= count && n >= 2;
    for (std::size_t g = 1; group && g < G; ++g) group = length(i + g) == n;
    if (group) {
      gather(std::integral_constant<std::size_t, G>{}, i, n);
      i += G;
      continue;
    }
    if (n >= 2) gather(std::integral_constant<std::size_t, 1>{}, i, n);
    ++i;
  }
}

// Whether line l needs the full Newton step: whether, at any of its links, the geometric stiffness
// g = tension / length reaches `ratio` (a tenth) of the particle's mass m. g / m is (c h / r)^2, the square
// of how many links a sideways wave (speed c = sqrt(T / mu)) crosses in a substep: below a third
// of a link the tridiagonal step keeps a kink from growing, and g changes the step by a tenth at
// most. (hang2 256: most rows are below it, every column above; the strains it reaches do not
// change. Rest lengths stand in for lengths.)
bool needsFullStep(const SolverScratch::LineFamily& lines, std::size_t l, const Real* mass, Real ratio) {
  for (std::size_t k = lines.start[l]; k + 1 < lines.start[l + 1]; ++k) {
    if (-lines.tension[k] >= ratio * lines.rest[k] * mass[lines.particle[k]]) return true;
  }
  return false;
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

void beginSubstep(SolverScratch& scratch) {
  for (SolverScratch::LineFamily& lines : scratch.lines) {
    lines.tension.swap(lines.tensionSum);
    std::fill(lines.tensionSum.begin(), lines.tensionSum.end(), 0.0f);
  }
}

void step(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, bool geometricStiffness,
          bool full, Workers& workers) {
  ParticleState& s = cloth.state;
  const bool fullStep = full && geometricStiffness;
  if (geometricStiffness) {
    const std::size_t rows = scratch.lineStride / 4 * static_cast<std::size_t>(workers.threads());
    if (scratch.lineStiff.size() < rows) scratch.lineStiff.resize(rows);
    for (SolverScratch::LineFamily& lines : scratch.lines) {  // sized here alone (zero: no tension yet)
      lines.tension.resize(lines.rest.size(), 0.0f);
      lines.tensionSum.resize(lines.rest.size(), 0.0f);
    }
  }
  for (SolverScratch::LineFamily& lines : scratch.lines) {
    if (lines.start.size() < 2) continue;
    const std::size_t count = lines.start.size() - 1;
    // Shared out only where each thread gets a few thousand links: below that, waking a helper
    // costs more than it saves.
    const std::size_t perLine = std::max<std::size_t>(lines.particle.size() / count, 1);
    const std::size_t grain = std::max<std::size_t>(2048 / perLine, 1);
    // The lines taut enough to need the full step (needsFullStep) are solved first, then the
    // others, each share taken by the workers in blocks: a full step costs about twice a
    // tridiagonal one, and the taut lines bunch together (near the pins).
    lines.order.resize(count);
    std::size_t taut = 0;
    if (fullStep) {
      lines.taut.resize(count);
      workers.run(
          count,
          [&](std::size_t first, std::size_t last, int) {
            for (std::size_t l = first; l < last; ++l) {
              lines.taut[l] = needsFullStep(lines, l, s.mass.data(), scratch.fullStepRatio) ? 1 : 0;
            }
          },
          grain);
      for (std::size_t l = 0; l < count; ++l) {
        if (lines.taut[l]) lines.order[taut++] = static_cast<std::uint32_t>(l);
      }
      for (std::size_t l = 0, slack = taut; l < count; ++l) {
        if (!lines.taut[l]) lines.order[slack++] = static_cast<std::uint32_t>(l);
      }
    } else {
      std::iota(lines.order.begin(), lines.order.end(), 0u);
    }
    for (const bool stiff : {true, false}) {
      const std::size_t from = stiff ? 0 : taut, to = stiff ? taut : count;
      if (from == to) continue;
      // Eight lines a block (whole groups for the vector solves), taken by whichever thread is free.
      workers.runShared(
          to - from, 8,
          [&](std::size_t first, std::size_t last, int thread) {
            const Real alpha = xpbd ? alphaTilde : 0.0;
            const std::size_t slice = scratch.lineStride * static_cast<std::size_t>(thread);
            const std::uint32_t* line = lines.order.data() + from + first;
            if (stiff) {
              inGroups<kLanes>(
                  lines, line, last - first, xpbd,
                  [&]<std::size_t G>(std::integral_constant<std::size_t, G>, const auto& p, const auto& rest,
                                     const auto& lambda, const auto& offset, std::size_t n) {
                    std::array<const float*, G> tension{};
                    std::array<float*, G> tensionSum{};
                    for (std::size_t g = 0; g < G; ++g) {
                      tension[g] = lines.tension.data() + offset[g];
                      tensionSum[g] = lines.tensionSum.data() + offset[g];
                    }
                    solveStiffLines<G>(s, p, rest, lambda, tension, tensionSum, n, stiffness, alpha,
                                       scratch.lineStiff.data() + slice / 4);
                  });
            } else {
              // With geometric stiffness every solve adds its multipliers to the tension sums.
              inGroups<4>(lines, line, last - first, xpbd,
                          [&]<std::size_t G>(std::integral_constant<std::size_t, G>, const auto& p, const auto& rest,
                                             const auto& lambda, const auto& offset, std::size_t n) {
                            std::array<float*, G> tensionSum{};
                            for (std::size_t g = 0; geometricStiffness && g < G; ++g) {
                              tensionSum[g] = lines.tensionSum.data() + offset[g];
                            }
                            solveLines<G>(s, p, rest, lambda, tensionSum, n, stiffness, alpha,
                                          scratch.lineNormal.data() + slice, scratch.lineUpper.data() + slice,
                                          scratch.lineSolution.data() + slice);
                          });
            }
          },
          grain);
    }
  }
}

void solveLoose(Cloth& cloth, const SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde,
                Real* looseLambda) {
  ParticleState& s = cloth.state;
  const std::vector<DistanceConstraint>& stretch = cloth.rest.of(ConstraintKind::stretch);
  for (const std::uint32_t k : scratch.looseStretch) {
    if (xpbd && looseLambda) {
      position::projectCompliant(s.position, s.inverseMass, stretch[k], alphaTilde, looseLambda[k]);
    } else {
      position::projectDistance(s.position, s.inverseMass, stretch[k], stiffness);
    }
  }
}

void solve(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, bool geometricStiffness,
           Workers& workers, Real* looseLambda) {
  // Two Newton steps: rows, columns, rows, columns. One leaves enough of the linearisation's error
  // that, where the cloth moves fast (a whipping hem), it grows from substep to substep; after two
  // it does not (docs/performance.md). With geometric stiffness the first step is the full Newton
  // step (which keeps kinks from growing) and the second the tridiagonal one (which only refines the
  // lengths): taking both full costs 1.7 times as much on hang2 for no stiffer a cloth.
  step(cloth, scratch, stiffness, xpbd, alphaTilde, geometricStiffness, true, workers);
  step(cloth, scratch, stiffness, xpbd, alphaTilde, geometricStiffness, false, workers);
  solveLoose(cloth, scratch, stiffness, xpbd, alphaTilde, looseLambda);
}

}  // namespace drape::sim::lines
