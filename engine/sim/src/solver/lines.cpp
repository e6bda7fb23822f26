#include "solver/lines.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <type_traits>
#include <vector>

#include <glm/geometric.hpp>

#include "invariant.hpp"
#include "solver/lines_wide.hpp"
#include "solver/pair_order.hpp"
#include "solver/position_model.hpp"
#include "solver/stiff_lanes.hpp"

namespace drape::sim::lines {

namespace {

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// A line's particles and links, read from the cloth's stretch constraints in line order (build):
// link k joins particle k, its a, to particle k + 1, its b.
struct Line {
  const DistanceConstraint* link = nullptr;
  ParticleIndex operator[](std::size_t k) const { return k == 0 ? link[0].a : link[k - 1].b; }
};

// The spans of a line held at both ends: from a held particle over free ones to the next held one
// (between two fingers, or a pin and a finger). With the seed's model (no compliance) a straight
// span's system is singular (every link pulling alike moves nothing) and a nearly straight one's
// nearly so. Pulled past its length, Thomas' algorithm puts the span's whole error in its last row,
// whose pivot is (nearly) 0: either the links but the last are made exact and the last takes all
// the others' stretch, or the tiny pivot's multiplier throws the span sideways (Newton's step for a
// taut string's length: a kink of angle a changes the length by a per unit of sideways move, so the
// step moves it error / a, far past where the length is met). A sheet pulled taut between a pinned
// side and fingers never settled: its links ran between 0.13 and 2.8 times their rest length.
//
// settleHeldSpan keeps a span's step only where it mends the span, by a measure whose
// Gauss-Newton step the line's step is: with the seed's model the span's summed squared error,
// sum_k C_k^2; with XPBD (alpha~ > 0)
//   f(dx) = 1/2 dx^T M dx + sum_k (C_k(x + dx) + alpha~ lambda_k)^2 / (2 alpha~),
// from where the particles are, with the multipliers lambda so far (its stationary point is
// (J M^-1 J^T + alpha~) dlambda = -(C + alpha~ lambda), dx = M^-1 J^T dlambda: the line's step).
// Where the full step does not lower it, the span's system is solved again with mu added to its
// diagonal (Levenberg-Marquardt: mu 1e-3, 1e-2, ... 1e2 times the span's mean diagonal) until the
// step does, or the span takes none. A healthy step stands bit for bit. A damped step shortens the
// moves of the nearly singular directions (the kinks, the span's uniform stretch, which no move
// changes) and keeps the others': a straight span pulled past its length comes out evenly
// stretched. Scaling the whole step down instead (1/2, 1/4, ... of it) mended the span but left
// it uneven: a 32 x 32 sheet held 5 % past its length between a pinned side and fingers ended with
// its rows from 0.886 to 1.211 times their rest length (now 1.045 to 1.054), and a fabric's (XPBD)
// from 1.032 to 1.066 (now 1.050 to 1.050). XPBD's compliance makes the system regular, but a
// stiff fabric's only just (alpha~ about 6e-4 of the diagonal for cotton at 32 x 32): pulled at
// 1 m/s, its rows were thrown from 0.16 to 3.5 times their length within 0.15 s (now 1.148 to
// 1.152, the pull's 15 %). With geometric stiffness (a stretch target) the full step is no guard: a
// line with a held span takes this step instead (hasHeldSpan).
//
// Pushed shorter than its links instead (fingers closing on a cloth), a straight span is as
// singular: the full step made every link but one exact and turned that one round (its particle
// carried through its neighbour, the link its length again, so the summed error read 0), and the
// cloth beside it took the shortfall: the shipped desk's crumple, a step after its six fingers
// touched down and before they had moved 2 mm, had links 44 % long between them. A step that turns
// a link of the span round is now refused, and a span short on the whole also tries the even step
// (below), which spreads the shortfall over its links.
constexpr Real kFirstDamping = 1e-3, kLastDamping = 1e2;

struct SpanScratch {
  std::vector<Vec3> move;
  std::vector<Real> step;  // the multipliers' steps tried, and Thomas' upper diagonal
};

// The span of links link[first, last] (its first link's a and last link's b held), its solution
// (the multipliers' steps over `stiffness`) strided; `lambda` the line's multipliers (XPBD),
// `start` the positions at the substep's start (XPBD's directions, position::alongStart).
void settleHeldSpan(const DistanceConstraint* link, std::size_t first, std::size_t last, const Vec3* x,
                    const Vec3* start, const Real* w, const MassReal* mass, const Vec3* normal, Real* solution,
                    std::size_t stride, Real stiffness, Real alphaTilde, const Real* lambda, SpanScratch& scratch) {
  const std::size_t m = last - first + 1;
  const bool compliant = alphaTilde > 0.0;
  const auto lambdaOf = [&](std::size_t i) { return lambda ? lambda[first + i] : 0.0; };
  const auto normalOf = [&](std::size_t i) { return normal[(first + i) * stride]; };
  // The measure after the moves of the multipliers' steps dl[0, m); and, if asked, the links'
  // errors (XPBD: with their compliance's share) added up.
  const auto measure = [&](const Real* dl, Real* errors = nullptr) {
    scratch.move.assign(m + 1, Vec3{0.0});
    Vec3* move = scratch.move.data();
    for (std::size_t i = 0; i < m; ++i) {
      const DistanceConstraint& c = link[first + i];
      const Vec3 along = compliant ? position::alongStart(normalOf(i), start[c.a], start[c.b], lambdaOf(i) + dl[i],
                                                          w[c.a] + w[c.b], c.restLength)
                                   : normalOf(i);
      move[i] -= w[c.a] * (along * dl[i]);
      move[i + 1] += w[c.b] * (along * dl[i]);
    }
    Real sum = 0.0;
    for (std::size_t i = 1; compliant && i < m; ++i) {
      sum += 0.5 * static_cast<Real>(mass[link[first + i].a]) * glm::dot(move[i], move[i]);
    }
    for (std::size_t i = 0; i < m; ++i) {
      const DistanceConstraint& c = link[first + i];
      const Vec3 d = x[c.b] - x[c.a] + move[i + 1] - move[i];
      // A link the step turns round (its particle carried through its neighbour) may come out its
      // length, but the cloth is folded through itself there: no such step is taken. (A link whose
      // particles coincide has no direction, and no way round to be turned.)
      const Vec3 along = normalOf(i);
      if (glm::dot(along, along) > 0.0 && !(glm::dot(d, along) > 0.0)) return std::numeric_limits<Real>::infinity();
      const Real e = glm::length(d) - c.restLength + alphaTilde * lambdaOf(i);
      if (errors) *errors += e;
      sum += compliant ? e * e / (2.0 * alphaTilde) : e * e;
    }
    return sum;
  };
  scratch.step.assign(3 * m, 0.0);
  Real* dl = scratch.step.data();
  Real* upper = dl + m;
  Real* even = dl + 2 * m;
  Real mean = 0.0;                         // the span's mean error, as it is
  const Real before = measure(dl, &mean);  // (no step)
  mean /= static_cast<Real>(m);
  // Thomas' algorithm on the span's rows with mu on the diagonal, as solveLines' (its ends held:
  // nothing couples beyond), for each link's error less `shift`, into out; a pivot the system
  // leaves (nearly) 0 is its diagonal, as in solveLines. Taken as the full step is: `stiffness` of
  // it (the seed's share of the violation a sweep corrects; 1 with XPBD).
  const auto solveSpan = [&](Real mu, Real shift, Real* out) {
    Real previousUpper = 0.0, previousStep = 0.0, previousCoupling = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      const DistanceConstraint& c = link[first + i];
      const Real diagonal = w[c.a] + w[c.b] + alphaTilde + mu;
      Real pivot = diagonal - previousCoupling * previousUpper;
      if (!(pivot > 1e-9 * diagonal)) pivot = diagonal;
      const Real coupling = i + 1 < m ? -w[c.b] * glm::dot(normalOf(i), normalOf(i + 1)) : 0.0;
      const Real rightHand = -(glm::length(x[c.b] - x[c.a]) - c.restLength) - alphaTilde * lambdaOf(i) + shift;
      upper[i] = coupling / pivot;
      out[i] = (rightHand - previousCoupling * previousStep) / pivot;
      previousCoupling = coupling;
      previousUpper = upper[i];
      previousStep = out[i];
    }
    for (std::size_t i = m - 1; i-- > 0;) out[i] -= upper[i] * out[i + 1];
    for (std::size_t i = 0; i < m; ++i) out[i] *= stiffness;
  };
  const auto keep = [&](const Real* step) {
    for (std::size_t i = 0; i < m; ++i) solution[(first + i) * stride] = step[i] / stiffness;
  };
  for (std::size_t i = 0; i < m; ++i) dl[i] = solution[(first + i) * stride] * stiffness;
  const Real full = measure(dl);
  // A span pushed shorter than its links (fingers closing on it): where it lies straight, no move
  // along it shortens it, and the full step makes every link but one exact and folds that one
  // back through its neighbour (which the measure refuses), or piles the shortfall on a few. The
  // even step spreads it over every link alike (each link's error less the span's mean: a system
  // the straight span can solve), the least summed error of any move along a straight span. Where
  // the span is bent and can take its links' lengths back by a move (it buckles), the full step
  // does better and is kept.
  if (mean < 0.0) {
    solveSpan(0.0, mean, even);
    const Real evenly = measure(even);
    if (evenly < before && !(full <= evenly)) {
      keep(even);
      return;
    }
  }
  if (full < before) return;
  Real meanDiagonal = 0.0;
  for (std::size_t i = 0; i < m; ++i) meanDiagonal += w[link[first + i].a] + w[link[first + i].b];
  meanDiagonal /= static_cast<Real>(m);
  for (Real damping = kFirstDamping; damping <= kLastDamping; damping *= 10.0) {
    solveSpan(damping * meanDiagonal, 0.0, dl);
    if (measure(dl) < before) {
      keep(dl);
      return;
    }
  }
  for (std::size_t i = 0; i < m; ++i) solution[(first + i) * stride] = 0.0;
}

// Every held span of a line (settleHeldSpan), its links link[0, links), its solution strided.
void settleHeldSpans(const DistanceConstraint* link, std::size_t links, const ParticleState& s, const Real* w,
                     const Vec3* normal, Real* solution, std::size_t stride, Real stiffness, Real alphaTilde,
                     const Real* lambda) {
  thread_local SpanScratch scratch;
  for (std::size_t k = 0; k < links;) {
    if (w[link[k].a] != 0.0) {
      ++k;
      continue;
    }
    std::size_t last = k;
    while (last < links && w[link[last].b] > 0.0) ++last;
    if (last == links) return;  // it runs to the line's free end
    if (last > k) {
      settleHeldSpan(link, k, last, s.position.data(), s.previousPosition.data(), w, s.mass.data(), normal, solution,
                     stride, stiffness, alphaTilde, lambda, scratch);
    }
    k = last + 1;
  }
}

// Solves G lines of n particles each in place, interleaved: line g has particles p[g][0..n) and
// links p[g].link[0..n-2]. Each line's arithmetic is the same whatever G is; interleaving only lets the core
// overlap the lines' chains of divisions (Thomas' recurrence is serial within a line).
// Scratch arrays hold (n - 1) * G entries, link k of line g at k * G + g.
//
// The steps of spans held at both ends are taken only as far as they mend them (settleHeldSpans),
// whatever the model: a line with a held span never takes the full step (hasHeldSpan).
// With kAlongStart (XPBD) each link moves its particles along its direction at the substep's start
// where it is slack enough (position::alongStart), which keeps the cloth's angular momentum:
// dx_k = w_k (dlambda_{k-1} n0_{k-1} - dlambda_k n0_k), dlambda from the system above.
template <std::size_t G, bool kAlongStart>
void solveLines(ParticleState& s, const std::array<Line, G>& p, const std::array<Real*, G>& lambda,
                const std::array<float*, G>& summed, bool restart, std::size_t n, Real stiffness, Real alphaTilde,
                Vec3* normal, Real* upper, Real* solution) {
  const std::size_t links = n - 1;
  Vec3* x = s.position.data();
  const Real* w = s.inverseMass.data();
  // Directions, diagonal (in upper) and right-hand side (in solution). A link whose particles
  // coincide, or that nothing can move, gets the row of the identity and no correction. And how
  // many of each line's particles are held (settleHeldSpans: a line with two may have a span).
  std::array<int, G> held{};
  for (std::size_t k = 0; k < links; ++k) {
    for (std::size_t g = 0; g < G; ++g) {
      const std::size_t at = k * G + g;
      const DistanceConstraint& c = p[g].link[k];
      const Vec3 d = x[c.b] - x[c.a];
      const Real length2 = glm::dot(d, d);
      const Real diagonal = w[c.a] + w[c.b] + alphaTilde;
      held[g] += (k == 0 && w[c.a] == 0.0) + (w[c.b] == 0.0);
      if (length2 > 1e-20 && diagonal > 0.0) {
        const Real length = std::sqrt(length2);
        normal[at] = d * (1.0 / length);
        upper[at] = diagonal;
        solution[at] = -(length - c.restLength) - (lambda[g] ? alphaTilde * lambda[g][k] : 0.0);
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
      // Only a span between two held particles, straight, makes the system singular, in its last
      // row; that link is then corrected as if alone (and the span is mended below).
      if (!(pivot > 1e-9 * diagonal)) pivot = diagonal;
      const Real inverse = 1.0 / pivot;
      const Real coupling = k + 1 < links ? -w[p[g].link[k].b] * glm::dot(normal[at], normal[at + G]) : 0.0;
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
  for (std::size_t g = 0; g < G; ++g) {
    if (held[g] >= 2) {
      settleHeldSpans(p[g].link, links, s, w, normal + g, solution + g, G, stiffness, alphaTilde, lambda[g]);
    }
  }
  for (std::size_t k = 0; k < links; ++k) {
    for (std::size_t g = 0; g < G; ++g) {
      const std::size_t at = k * G + g;
      const Real dl = solution[at] * stiffness;
      if (lambda[g]) lambda[g][k] += dl;
      if (summed[g]) summed[g][k] = static_cast<float>((restart ? 0.0f : summed[g][k]) + dl);
      const DistanceConstraint& c = p[g].link[k];
      Vec3 along = normal[at];
      if constexpr (kAlongStart) {
        // (The substep's multiplier so far; a caller that keeps none has only this step's.)
        along = position::alongStart(along, s.previousPosition[c.a], s.previousPosition[c.b],
                                     lambda[g] ? lambda[g][k] : dl, w[c.a] + w[c.b], c.restLength);
      }
      const Vec3 push = along * dl;
      x[c.a] -= push * w[c.a];
      x[c.b] += push * w[c.b];
    }
  }
}

// The full Newton step runs in single precision, lines side by side in vector lanes
// (stiff_lanes.hpp): eight to an AVX register where the CPU has AVX (cpuHasAvx), else four to an SSE
// one. It only has to find the direction the second, double-precision step refines (the links'
// lengths it leaves are that step's to correct).
//
// One full Newton step of G lines' projections from where their particles are now, geometric
// stiffness included: with dx the particles' moves and l the links' multipliers,
//   K dx - J^T l = 0,   J dx + alpha~ l = -(C + alpha~ lambda),
//   K = M + sum_k G_k (on link k's two particles: [G, -G; -G, G]), G_k = g_k (I - n_k n_k^T),
// g_k = the link's tension (times h^2: the substep's multipliers so far, at its first step the last
// substep's) over its length (Tournier et al.
// 2015, Andrews et al. 2017). Without G this is solveLines' tridiagonal system; with it a
// particle's sideways move drags its neighbours, as a taut string's does. The unknowns are
// eliminated in the order x_0, x_1, l_0, x_2, l_1, ...: a front of one particle and one link (a
// 3 x 3 inverse and a scalar pivot), so a held particle (whose unknowns drop out) never leaves a
// link's multiplier without a pivot. rows holds n rows; the lines' data is gathered into lanes,
// solved by solveStiffLanes W (4 or 8) lanes at once (the first G filled; the others hold a held
// particle and no link), and the moves and multipliers scattered back.
// (FixedG: the number of lines G when it is known at compile time, a full group; 0: given as count.)
template <std::size_t W, std::size_t FixedG>
void solveStiffLines(ParticleState& s, std::size_t count, const std::array<Line, W>& p,
                     const std::array<Real*, W>& lambda, const std::array<float*, W>& tension, bool restart,
                     bool sumTension, std::size_t n, Real stiffness, Real alphaTilde, SolverScratch::StiffRows* rows,
                     bool consecutive) {
  static_assert(W <= SolverScratch::StiffRows::kLanes && FixedG <= W);
  // Eight lines whose particles at each k are consecutive (p[g][k] = p[0][k] + g) are gathered and
  // scattered eight particles at a time (lines_wide.cpp): the same bits as below.
  constexpr bool kWide = W == 8 && FixedG == 8;
  const std::size_t G = FixedG != 0 ? FixedG : count;
  using Row = SolverScratch::StiffRows;
  Vec3* x = s.position.data();
  const Real* w = s.inverseMass.data();
  const MassReal* mass = s.mass.data();
  const std::size_t links = n - 1;
  // Gathered first: each link's direction, value and geometric stiffness, each particle's mass.
  // Each line's system is solved in units of its first particle's mass (K / s, alpha~ s, l / s,
  // s = that mass), so that single precision holds whatever the cloth weighs.
  std::array<Real, W> unitMass, perUnitMass;
  unitMass.fill(1.0);
  perUnitMass.fill(1.0);
  float alpha[W]{};
  for (std::size_t g = 0; g < G; ++g) {
    unitMass[g] = mass[p[g][0]] > 0.0 ? mass[p[g][0]] : 1.0;
    perUnitMass[g] = 1.0 / unitMass[g];
    alpha[g] = static_cast<float>(alphaTilde * unitMass[g]);
  }
  // Each link's difference (in double: the particles' distance from the origin may be a thousand
  // links), rest length, tension, and whether anything can move it; solveStiffLanes makes of them
  // the link's direction, value and geometric stiffness (normalise). Each line's particle at k + 1
  // is carried over as the next link's first. Lanes no line fills hold a held particle and no link.
  const bool wide = kWide && consecutive;
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "the wide gather reads positions as x, y, z doubles");
  if (wide) {
    std::array<const DistanceConstraint*, W> lineLinks{};
    for (std::size_t g = 0; g < W; ++g) lineLinks[g] = p[g].link;
    gatherConsecutiveWide(rows, n, reinterpret_cast<const double*>(x), w, mass, p[0].link, lineLinks.data(),
                          lambda.data(), tension.data(), perUnitMass.data(), alphaTilde);
  } else {
    std::array<Vec3, W> from;
    std::array<Real, W> fromW;
    for (std::size_t g = 0; g < G; ++g) {
      from[g] = x[p[g][0]];
      fromW[g] = w[p[g][0]];
    }
    for (std::size_t k = 0; k < n; ++k) {
      Row& r = rows[k];
      for (std::size_t g = 0; g < G; ++g) {
        r.v[0][g] = static_cast<float>(mass[p[g][k]] * perUnitMass[g]);  // (StiffRows: what v holds before)
        r.v[1][g] = fromW[g] > 0.0 ? 1.0f : 0.0f;
        if (k == links) {
          r.nx[g] = r.ny[g] = r.nz[g] = r.yl[g] = r.g[g] = r.schur[g] = 0.0f;
          continue;
        }
        const DistanceConstraint& c = p[g].link[k];
        const Vec3 to = x[c.b];
        const Real toW = w[c.b];
        const Vec3 d = to - from[g];
        r.nx[g] = static_cast<float>(d.x);
        r.ny[g] = static_cast<float>(d.y);
        r.nz[g] = static_cast<float>(d.z);
        // C + alpha~ lambda = length - (rest - alpha~ lambda)
        r.yl[g] = static_cast<float>(c.restLength - (lambda[g] ? alphaTilde * lambda[g][k] : 0.0));
        // Pulled links only: a pushed one would make K indefinite.
        r.g[g] = static_cast<float>(std::max(-static_cast<Real>(tension[g][k]), 0.0) * perUnitMass[g]);
        r.schur[g] = fromW[g] + toW + alphaTilde > 0.0 ? 1.0f : 0.0f;
        from[g] = to;
        fromW[g] = toW;
      }
      for (std::size_t g = G; g < W; ++g) {
        r.v[0][g] = 1.0f;
        r.v[1][g] = r.nx[g] = r.ny[g] = r.nz[g] = r.yl[g] = r.g[g] = r.schur[g] = 0.0f;
      }
    }
  }
  // A held particle or a dead link is masked, not branched on.
  if constexpr (W == 8) {
    solveStiffLanesWide(rows, n, alpha);
  } else {
    solveStiffLanes<Narrow>(rows, n, load<Narrow>(alpha));
  }
  // A dead link's multiplier comes out 0 and is added all the same; a held particle is not touched
  // (its move is 0 too, but it must stay put even if something upstream went non-finite).
  std::array<Real, W> multiplierScale{};
  for (std::size_t g = 0; g < G; ++g) multiplierScale[g] = unitMass[g] * stiffness;
  if (wide) scatterConsecutiveWide(rows, n, reinterpret_cast<double*>(x), w, p[0].link, stiffness);
  for (std::size_t j = 0; j < n; ++j) {
    const Row& r = rows[j];
    for (std::size_t g = 0; g < G; ++g) {
      if (!wide && w[p[g][j]] > 0.0) x[p[g][j]] += Vec3{r.yx[0][g], r.yx[1][g], r.yx[2][g]} * stiffness;
      if (j == 0) continue;
      const Real multiplier = static_cast<Real>(r.yl[g]) * multiplierScale[g];
      if (lambda[g]) lambda[g][j - 1] += multiplier;
      if (sumTension) tension[g][j - 1] = static_cast<float>((restart ? 0.0f : tension[g][j - 1]) + multiplier);
    }
  }
}

// Lines line[0, G) of a family: their links (in `stretch`, the cloth's stretch constraints), their
// multipliers (at their slots; null without XPBD) and their first link's index in `stretch` (where
// their tension is, Cloth::stretchTension), in arrays of N.
template <std::size_t N>
struct LineData {
  std::array<Line, N> p{};
  std::array<Real*, N> lambda{};
  std::array<std::size_t, N> firstLink{};
};
template <std::size_t N>
LineData<N> lineData(SolverScratch::LineFamily& lines, const DistanceConstraint* stretch, const std::uint32_t* line,
                     std::size_t G, bool xpbd) {
  LineData<N> d;
  for (std::size_t g = 0; g < G; ++g) {
    d.firstLink[g] = lines.firstLink(line[g]);
    d.p[g].link = stretch + d.firstLink[g];
    d.lambda[g] = xpbd ? lines.lambda.data() + lines.start[line[g]] : nullptr;
  }
  return d;
}

// The lines line[0, count) of a family, W at a time where W in a row are equally long (G = W),
// else one (G = 1): solve(std::integral_constant<std::size_t, G>, lines, lambdas, firstLinks, n),
// each array holding G lines' (lambdas null without XPBD; LineData). A line's arithmetic does not depend
// on which lines it is solved beside. (The vector solve takes up to W in a row instead: inLanes.)
template <std::size_t W, class Solve>
void inGroups(SolverScratch::LineFamily& lines, const DistanceConstraint* stretch, const std::uint32_t* line,
              std::size_t count, bool xpbd, Solve&& solve) {
  constexpr std::size_t G = W;
  const auto length = [&](std::size_t i) { return lines.start[line[i] + 1] - lines.start[line[i]]; };
  const auto gather = [&]<std::size_t N>(std::integral_constant<std::size_t, N> size, std::size_t i, std::size_t n) {
    const LineData<N> d = lineData<N>(lines, stretch, line + i, N, xpbd);
    solve(size, d.p, d.lambda, d.firstLink, n);
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

// The lines line[0, count) of a family, up to W at a time, as many equally long ones as follow
// each other: solve(G, lines, lambdas, firstLinks, n, ids), each array holding W lines' of which the
// first G are filled (lambdas null without XPBD), and ids their indices.
// A lane left empty costs as much as a filled one, so a short group beats lines one by one.
template <std::size_t W, class Solve>
void inLanes(SolverScratch::LineFamily& lines, const DistanceConstraint* stretch, const std::uint32_t* line,
             std::size_t count, bool xpbd, Solve&& solve) {
  const auto length = [&](std::size_t i) { return lines.start[line[i] + 1] - lines.start[line[i]]; };
  for (std::size_t i = 0; i < count;) {
    const std::size_t n = length(i);
    if (n < 2) {
      ++i;
      continue;
    }
    std::size_t G = 1;
    while (G < W && i + G < count && length(i + G) == n) ++G;
    const LineData<W> d = lineData<W>(lines, stretch, line + i, G, xpbd);
    solve(G, d.p, d.lambda, d.firstLink, n, line + i);
    i += G;
  }
}

// Whether line l needs the full Newton step: whether, at any of its links, the geometric stiffness
// g = tension / length reaches `ratio` (a tenth) of the particle's mass m. g / m is (c h / r)^2, the square
// of how many links a sideways wave (speed c = sqrt(T / mu)) crosses in a substep: below a third
// of a link the tridiagonal step keeps a kink from growing, and g changes the step by a tenth at
// most. (hang2 256: most rows are below it, every column above; the strains it reaches do not
// change. Rest lengths stand in for lengths.)
bool needsFullStep(const SolverScratch::LineFamily& lines, const DistanceConstraint* stretch,
                   const float* stretchTension, std::size_t l, const MassReal* mass, Real ratio) {
  const DistanceConstraint* link = stretch + lines.firstLink(l);
  const float* tension = stretchTension + lines.firstLink(l);
  for (std::size_t k = 0, links = lines.start[l + 1] - lines.start[l] - 1; k < links; ++k) {
    if (-tension[k] >= ratio * link[k].restLength * mass[link[k].a]) return true;
  }
  return false;
}

// Whether line l has a span held at both ends (a held particle, free ones, a held one: between two
// fingers, or a pin and a finger). Such a span, straight, makes the full step's system singular
// as it does the tridiagonal one's (every link pulling alike moves nothing), and the geometric
// stiffness, which acts across the links only, does not make it regular: pushed shorter, the full
// step made all its links but one exact and turned that one round; pulled past its length, the
// tiny pivots threw it sideways. Four fingers pushing the desk's corners in and drawing them out
// (the `spread` gesture) with a stretch target had links at 2.5 times their length the step the
// fingers came down and diverged at 2.38 s (at 2 x 8 and five other settings; 4 x 2 ended with
// links 1,990 times their length). Such a line takes the tridiagonal step, whose held spans are
// mended (settleHeldSpans).
bool hasHeldSpan(const SolverScratch::LineFamily& lines, const DistanceConstraint* stretch, std::size_t l,
                 const Real* w) {
  const DistanceConstraint* link = stretch + lines.firstLink(l);
  const std::size_t links = lines.start[l + 1] - lines.start[l] - 1;
  bool heldBefore = links > 0 && w[link[0].a] == 0.0, freeSince = false;
  for (std::size_t k = 0; k < links; ++k) {
    if (w[link[k].b] == 0.0) {
      if (heldBefore && freeSince) return true;
      heldBefore = true;
      freeSince = false;
    } else {
      freeSince = true;
    }
  }
  return false;
}

}  // namespace

bool cpuHasAvx() {
#if (defined(__x86_64__) || defined(__i386__)) && defined(DRAPE_WIDE_LANES)
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx") != 0;  // and the system saves its registers
  }();
  return has;
#else
  return false;
#endif
}

namespace {

// The lines a cloth's stretch constraints make (build's rule, lines.hpp), walked from one end of
// each: per family its lines' starts, and every link in line order, each turned to point along its
// line, then the loose ones.
struct Walk {
  std::array<std::vector<std::uint32_t>, 2> start;  // per family, as LineFamily::start
  std::array<std::uint32_t, 2> linkBase{};
  std::vector<DistanceConstraint> ordered;  // the links of the lines, line by line; then the loose
  std::vector<std::uint32_t> from;          // where each came from in the stretch constraints
  std::vector<std::uint32_t> loose;         // the loose ones' places in `ordered`
  std::size_t longest = 0;                  // particles of the longest line
};

Walk walk(const ClothRest& rest) {
  const std::vector<DistanceConstraint>& stretch = rest.of(ConstraintKind::stretch);
  const std::size_t n = rest.particleCount();
  Walk w;
  // The links are taken in the order of their particles, not of the array: which join a line then
  // does not depend on the order the constraints come in, so walking again the order this gives
  // them gives the same lines.
  const std::vector<std::uint32_t> byPair = byParticlePair(stretch);
  w.ordered.reserve(stretch.size());
  w.from.reserve(stretch.size());
  std::array<std::vector<std::uint32_t>, 2> loose;
  for (int family = 0; family < 2; ++family) {
    std::vector<std::uint32_t>& starts = w.start[static_cast<std::size_t>(family)];
    w.linkBase[static_cast<std::size_t>(family)] = static_cast<std::uint32_t>(w.ordered.size());
    std::vector<std::uint8_t> degree(n, 0);
    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    std::vector<std::array<std::int64_t, 2>> next(n, {-1, -1});  // the constraints at each particle
    const auto inFamily = [&](const DistanceConstraint& c) {
      const Vec3 d = glm::abs(rest.restPosition(c.b) - rest.restPosition(c.a));
      return (d.x >= std::max(d.y, d.z)) == (family == 0);
    };
    // Where a particle has more than two links of the family, the two most nearly opposite are the
    // ones a line may take through it: on a drawn cloth's border at 45 degrees to the lattice, its
    // two links along the border rather than the row's that ends there, so that the border is one
    // line (taken as they came, many border links were loose, 28 of 129 on a square drawn at 45
    // degrees, and the loose pass after the lines undid them: docs/design.md, known limits).
    std::vector<std::array<std::int64_t, 2>> preferred(n, {-1, -1});
    {
      // Each particle's links of the family (by particle pair), counted, then filled.
      std::vector<std::uint32_t> start(n + 1, 0);
      for (const std::uint32_t k : byPair) {
        if (!inFamily(stretch[k])) continue;
        ++start[stretch[k].a + 1];
        ++start[stretch[k].b + 1];
      }
      for (std::size_t p = 0; p < n; ++p) start[p + 1] += start[p];
      std::vector<std::uint32_t> at(start[n]), fill(start.begin(), start.end() - 1);
      for (const std::uint32_t k : byPair) {
        if (!inFamily(stretch[k])) continue;
        at[fill[stretch[k].a]++] = k;
        at[fill[stretch[k].b]++] = k;
      }
      for (std::size_t p = 0; p < n; ++p) {
        if (start[p + 1] - start[p] <= 2) continue;
        Real best = 2.0;  // ties: the pair met first, in particle-pair order
        for (std::uint32_t i = start[p]; i < start[p + 1]; ++i) {
          for (std::uint32_t j = i + 1; j < start[p + 1]; ++j) {
            const DistanceConstraint &ci = stretch[at[i]], &cj = stretch[at[j]];
            const Vec3 di = rest.restPosition(ci.a == p ? ci.b : ci.a) - rest.restPosition(p);
            const Vec3 dj = rest.restPosition(cj.a == p ? cj.b : cj.a) - rest.restPosition(p);
            const Real cosine = glm::dot(di, dj) / (glm::length(di) * glm::length(dj));
            if (cosine < best) {
              best = cosine;
              preferred[p] = {at[i], at[j]};
            }
          }
        }
      }
    }
    const auto takes = [&](std::uint32_t p, std::uint32_t k) {
      return preferred[p][0] < 0 || preferred[p][0] == k || preferred[p][1] == k;
    };
    for (const std::uint32_t k : byPair) {
      const DistanceConstraint& c = stretch[k];
      if (!inFamily(c)) continue;
      const std::uint32_t ra = findRoot(parent, c.a), rb = findRoot(parent, c.b);
      if (degree[c.a] >= 2 || degree[c.b] >= 2 || ra == rb || !takes(c.a, k) || !takes(c.b, k)) {
        loose[static_cast<std::size_t>(family)].push_back(k);
        continue;
      }
      parent[ra] = rb;
      next[c.a][degree[c.a]++] = k;
      next[c.b][degree[c.b]++] = k;
    }
    // Walk each line from one of its ends, turning each link to point along it.
    std::vector<std::uint8_t> done(n, 0);
    std::uint32_t slots = 0;
    for (std::size_t first = 0; first < n; ++first) {
      if (degree[first] != 1 || done[first]) continue;
      starts.push_back(slots);
      std::size_t at = first;
      std::int64_t previous = -1;
      std::size_t length = 0;
      while (true) {
        done[at] = 1;
        ++slots;
        ++length;
        std::int64_t link = -1;
        for (std::int64_t candidate : next[at]) {
          if (candidate >= 0 && candidate != previous) link = candidate;
        }
        if (link < 0) break;
        DistanceConstraint c = stretch[static_cast<std::size_t>(link)];
        if (c.a != at) std::swap(c.a, c.b);
        w.ordered.push_back(c);
        w.from.push_back(static_cast<std::uint32_t>(link));
        at = c.b;
        previous = link;
      }
      w.longest = std::max(w.longest, length);
    }
    starts.push_back(slots);
  }
  for (const std::vector<std::uint32_t>& family : loose) {
    for (const std::uint32_t k : family) {
      w.loose.push_back(static_cast<std::uint32_t>(w.ordered.size()));
      const DistanceConstraint& c = stretch[k];
      w.ordered.push_back({std::min(c.a, c.b), std::max(c.a, c.b), c.restLength});  // from its lower particle
      w.from.push_back(k);
    }
  }
  return w;
}

// Moves values kept one a stretch constraint as the constraints move (to[k] came from from[k]).
template <class T>
void follow(std::vector<T>& values, const std::vector<std::uint32_t>& from) {
  std::vector<T> moved(from.size());
  for (std::size_t k = 0; k < from.size(); ++k) moved[k] = values[from[k]];
  values.swap(moved);
}

}  // namespace

void order(ClothRest& rest, std::vector<std::uint32_t>* source, std::vector<float>* tension) {
  Walk w = walk(rest);
  if (source && source->size() == w.from.size()) follow(*source, w.from);
  // A tension that is not one a constraint is stale: none.
  if (tension) {
    if (tension->size() == w.from.size()) {
      follow(*tension, w.from);
    } else {
      tension->clear();
    }
  }
  rest.constraints[static_cast<std::size_t>(ConstraintKind::stretch)].swap(w.ordered);
}

void build(const Cloth& cloth, SolverScratch& scratch, int threads) {
  const std::vector<DistanceConstraint>& stretch = cloth.rest.of(ConstraintKind::stretch);
  Walk w = walk(cloth.rest);
  if constexpr (kCheckInvariants) {
    // The order the lines read: the one order (orderConstraints) already, each link turned.
    for (std::size_t k = 0; k < stretch.size(); ++k) {
      DRAPE_INVARIANT(w.from[k] == k && w.ordered[k] == stretch[k],
                      "the stretch constraints are in line order (orderConstraints)");
    }
  }
  for (std::size_t family = 0; family < 2; ++family) {
    SolverScratch::LineFamily& lines = scratch.lines[family];
    lines = {};
    lines.start = std::move(w.start[family]);
    lines.linkBase = w.linkBase[family];
  }
  scratch.looseStretch = std::move(w.loose);
  const std::size_t longest = w.longest;
  for (SolverScratch::LineFamily& lines : scratch.lines) {
    const std::size_t count = lines.start.size() - 1;
    if constexpr (kCheckInvariants) {
      // What the line solve reads: a line's links in order, each starting where the one before ends.
      for (std::size_t l = 0; l < count; ++l) {
        for (std::size_t k = 1; k + 1 < lines.start[l + 1] - lines.start[l]; ++k) {
          DRAPE_INVARIANT(stretch[lines.firstLink(l) + k].a == stretch[lines.firstLink(l) + k - 1].b,
                          "a line's links run end to end");
        }
      }
    }
    lines.besideNext.assign(count, 0);
    for (std::size_t l = 0; l + 1 < count; ++l) {
      const std::uint32_t length = lines.start[l + 1] - lines.start[l];
      bool beside = lines.start[l + 2] - lines.start[l + 1] == length;
      const Line here{stretch.data() + lines.firstLink(l)}, beyond{stretch.data() + lines.firstLink(l + 1)};
      for (std::uint32_t k = 0; beside && k < length; ++k) beside = beyond[k] == here[k] + 1;
      lines.besideNext[l] = beside ? 1 : 0;
    }
  }
  scratch.stiffLanes = cpuHasAvx() ? 8 : 4;
  scratch.lineStride = longest * 4;  // four lines interleaved
  const std::size_t slices = scratch.lineStride * static_cast<std::size_t>(std::max(threads, 1));
  scratch.lineNormal.assign(slices, Vec3{0.0});
  scratch.lineUpper.assign(slices, 0.0);
  scratch.lineSolution.assign(slices, 0.0);
}

void beginSubstep(SolverScratch& scratch) {
  for (SolverScratch::LineFamily& lines : scratch.lines) {
    lines.fresh = true;
    lines.ordered = false;
  }
}

void step(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, bool geometricStiffness,
          bool full, Workers& workers) {
  ParticleState& s = cloth.state;
  const DistanceConstraint* stretch = cloth.rest.of(ConstraintKind::stretch).data();
  const bool fullStep = full && geometricStiffness;
  if (geometricStiffness) {
    const std::size_t rows = scratch.lineStride / 4 * static_cast<std::size_t>(workers.threads());
    if (scratch.lineStiff.size() < rows) scratch.lineStiff.resize(rows);
    // Sized here alone (zero: no tension yet); a link on no line keeps a slot it never uses.
    cloth.stretchTension.resize(cloth.rest.of(ConstraintKind::stretch).size(), 0.0f);
  }
  for (SolverScratch::LineFamily& lines : scratch.lines) {
    if (lines.start.size() < 2) continue;
    const std::size_t count = lines.start.size() - 1;
    // Shared out only where each thread gets a few thousand links: below that, waking a helper
    // costs more than it saves.
    const std::size_t perLine = std::max<std::size_t>(lines.slots() / count, 1);
    const std::size_t grain = std::max<std::size_t>(2048 / perLine, 1);
    // The lines taut enough to need the full step (needsFullStep) are solved first, then the
    // others, each share taken by the workers in blocks: a full step costs about twice a
    // tridiagonal one, and the taut lines bunch together (near the pins).
    // The flags come from the tension at the substep's first full step (the last substep's) and
    // hold for the whole substep.
    if (fullStep && !lines.ordered) {
      lines.taut.resize(count);
      lines.order.resize(count);
      workers.run(
          count,
          [&](std::size_t first, std::size_t last, int) {
            for (std::size_t l = first; l < last; ++l) {
              lines.taut[l] =
                  needsFullStep(lines, stretch, cloth.stretchTension.data(), l, s.mass.data(), scratch.fullStepRatio) &&
                          !hasHeldSpan(lines, stretch, l, s.inverseMass.data())
                      ? 1
                      : 0;
            }
          },
          grain);
      std::size_t taut = 0;
      for (std::size_t l = 0; l < count; ++l) {
        if (lines.taut[l]) lines.order[taut++] = static_cast<std::uint32_t>(l);
      }
      for (std::size_t l = 0, slack = taut; l < count; ++l) {
        if (!lines.taut[l]) lines.order[slack++] = static_cast<std::uint32_t>(l);
      }
      lines.tautCount = taut;
      lines.ordered = true;
    } else if (!lines.ordered) {  // any order will do: every line takes the tridiagonal step
      lines.order.resize(count);
      std::iota(lines.order.begin(), lines.order.end(), 0u);
    }
    const std::size_t taut = fullStep ? lines.tautCount : 0;
    // A substep's first step starts its sum: it reads the last substep's and writes its own.
    const bool restart = lines.fresh;
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
              const auto solveStiff = [&]<std::size_t W>(std::integral_constant<std::size_t, W>) {
                inLanes<W>(lines, stretch, line, last - first, xpbd,
                           [&](std::size_t G, const auto& p, const auto& lambda, const auto& firstLink, std::size_t n,
                               const std::uint32_t* ids) {
                             // The tension is read and summed in the same array: a line's gather
                             // reads its links' before its scatter adds to them.
                             std::array<float*, W> tension{};
                             for (std::size_t g = 0; g < G; ++g) {
                               tension[g] = cloth.stretchTension.data() + firstLink[g];
                             }
                             StiffRow* rows = scratch.lineStiff.data() + slice / 4;
                             if (G == W) {
                               bool consecutive = true;
                               for (std::size_t g = 0; consecutive && g + 1 < W; ++g) {
                                 consecutive = ids[g + 1] == ids[g] + 1 && lines.besideNext[ids[g]];
                               }
                               solveStiffLines<W, W>(s, G, p, lambda, tension, restart, scratch.sumTension, n,
                                                     stiffness, alpha, rows, consecutive);
                             } else {
                               solveStiffLines<W, 0>(s, G, p, lambda, tension, restart, scratch.sumTension, n,
                                                     stiffness, alpha, rows, false);
                             }
                           });
              };
              if (scratch.stiffLanes == 8) {
                solveStiff(std::integral_constant<std::size_t, 8>{});
              } else {
                solveStiff(std::integral_constant<std::size_t, 4>{});
              }
            } else {
              // With geometric stiffness every solve adds its multipliers to the tension sums.
              inGroups<4>(
                  lines, stretch, line, last - first, xpbd,
                  [&]<std::size_t G>(std::integral_constant<std::size_t, G>, const auto& p, const auto& lambda,
                                     const auto& firstLink, std::size_t n) {
                    std::array<float*, G> summed{};
                    for (std::size_t g = 0; geometricStiffness && scratch.sumTension && g < G; ++g) {
                      summed[g] = cloth.stretchTension.data() + firstLink[g];
                    }
                    Vec3* normal = scratch.lineNormal.data() + slice;
                    Real* upper = scratch.lineUpper.data() + slice;
                    Real* solution = scratch.lineSolution.data() + slice;
                    if (xpbd) {
                      solveLines<G, true>(s, p, lambda, summed, restart, n, stiffness, alpha, normal, upper, solution);
                    } else {
                      solveLines<G, false>(s, p, lambda, summed, restart, n, stiffness, alpha, normal, upper, solution);
                    }
                  });
            }
          },
          grain);
    }
    if (geometricStiffness) lines.fresh = false;
  }
}

void solveLoose(Cloth& cloth, const SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde,
                Real* looseLambda) {
  ParticleState& s = cloth.state;
  const std::vector<DistanceConstraint>& stretch = cloth.rest.of(ConstraintKind::stretch);
  for (const std::uint32_t k : scratch.looseStretch) {
    if (xpbd && looseLambda) {
      position::projectCompliant(s.position, s.previousPosition, s.inverseMass, stretch[k], alphaTilde, looseLambda[k]);
    } else {
      position::projectDistance(s.position, s.inverseMass, stretch[k], stiffness);
    }
  }
}

namespace {

// Whether some link of a line, one of whose particles is free to move, is longer than
// (1 + tolerance) times its rest length. The lines are shared among the workers as the steps share
// them; any that finds one stops the others looking.
bool stretchedBeyond(const Cloth& cloth, const SolverScratch& scratch, Real tolerance, Workers& workers) {
  const Vec3* x = cloth.state.position.data();
  const Real* w = cloth.state.inverseMass.data();
  const DistanceConstraint* stretch = cloth.rest.of(ConstraintKind::stretch).data();
  const Real scale = (1.0 + tolerance) * (1.0 + tolerance);
  std::atomic<bool> found{false};
  for (const SolverScratch::LineFamily& lines : scratch.lines) {
    if (lines.start.size() < 2) continue;
    workers.runShared(lines.start.size() - 1, 8, [&](std::size_t first, std::size_t last, int) {
      if (found.load(std::memory_order_relaxed)) return;
      bool beyond = false;
      for (std::size_t l = first; l < last; ++l) {
        const DistanceConstraint* link = stretch + lines.firstLink(l);
        for (std::size_t k = 0, links = lines.start[l + 1] - lines.start[l] - 1; k < links; ++k) {
          const DistanceConstraint& c = link[k];
          const Vec3 d = x[c.b] - x[c.a];
          const Real r = c.restLength;
          beyond |= glm::dot(d, d) > scale * (r * r) && w[c.a] + w[c.b] > 0.0;
        }
      }
      if (beyond) found.store(true, std::memory_order_relaxed);
    });
    if (found.load()) return true;
  }
  return false;
}

}  // namespace

int solve(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, bool geometricStiffness,
          Workers& workers, Real* looseLambda, const Extra& extra, const std::function<void()>& afterStep,
          PartClock* parts) {
  // Two Newton steps: rows, columns, rows, columns. One leaves enough of the linearisation's error
  // that, where the cloth moves fast (a whipping hem), it grows from substep to substep; after two
  // it does not (docs/performance.md). With geometric stiffness the first step is the full Newton
  // step (which keeps kinks from growing) and the second the tridiagonal one (which only refines the
  // lengths): taking both full costs 1.7 times as much on hang2 for no stiffer a cloth, unless the
  // tethers are projected after each (docs/design.md).
  const auto newtonStep = [&](bool full) {
    step(cloth, scratch, stiffness, xpbd, alphaTilde, geometricStiffness, full, workers);
    if (afterStep) afterStep();
  };
  newtonStep(true);
  newtonStep(extra.bothFull);
  int taken = 0;
  while (taken < extra.steps && stretchedBeyond(cloth, scratch, extra.tolerance, workers)) {
    newtonStep(true);
    ++taken;
  }
  if (!scratch.looseStretch.empty()) {
    PartClock untimed;
    (parts ? *parts : untimed).time(Stage::looseLinks, [&] {
      solveLoose(cloth, scratch, stiffness, xpbd, alphaTilde, looseLambda);
    });
  }
  return taken;
}

}  // namespace drape::sim::lines

namespace drape::sim {

int stiffSolveLanes() { return lines::cpuHasAvx() ? 8 : 4; }

}  // namespace drape::sim
