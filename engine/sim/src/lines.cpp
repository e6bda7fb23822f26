#include "lines.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

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
                const std::array<Real*, G>& lambda, std::size_t n, Real stiffness, Real alphaTilde, Vec3* normal,
                Real* upper, Real* solution) {
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
      const Vec3 push = normal[at] * dl;
      x[p[g][k]] -= push * w[p[g][k]];
      x[p[g][k + 1]] += push * w[p[g][k + 1]];
    }
  }
}

// Lines [first, last) of a family: four at a time where four in a row are equally long.
void solveFamily(ParticleState& s, SolverScratch::LineFamily& lines, std::size_t first, std::size_t last,
                 Real stiffness, bool xpbd, Real alphaTilde, Vec3* normal, Real* upper, Real* solution) {
  constexpr std::size_t G = 4;
  const auto length = [&](std::size_t l) { return lines.start[l + 1] - lines.start[l]; };
  const auto lambdaOf = [&](std::size_t l) { return xpbd ? lines.lambda.data() + lines.start[l] : nullptr; };
  const Real alpha = xpbd ? alphaTilde : 0.0;
  for (std::size_t l = first; l < last;) {
    const std::size_t n = length(l);
    bool group = l + G <= last && n >= 2;
    for (std::size_t g = 1; group && g < G; ++g) group = length(l + g) == n;
    if (group) {
      std::array<const ParticleIndex*, G> p{};
      std::array<const Real*, G> rest{};
      std::array<Real*, G> lambda{};
      for (std::size_t g = 0; g < G; ++g) {
        p[g] = lines.particle.data() + lines.start[l + g];
        rest[g] = lines.rest.data() + lines.start[l + g];
        lambda[g] = lambdaOf(l + g);
      }
      solveLines<G>(s, p, rest, lambda, n, stiffness, alpha, normal, upper, solution);
      l += G;
      continue;
    }
    if (n >= 2) {
      solveLines<1>(s, {lines.particle.data() + lines.start[l]}, {lines.rest.data() + lines.start[l]}, {lambdaOf(l)}, n,
                    stiffness, alpha, normal, upper, solution);
    }
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

void solve(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, Workers& workers,
           Real* looseLambda) {
  ParticleState& s = cloth.state;
  // Two Newton steps: rows, columns, rows, columns. One leaves enough of the linearisation's error
  // that, where the cloth moves fast (a whipping hem), it grows from substep to substep; after two
  // it does not (docs/performance.md).
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
            const std::size_t slice = scratch.lineStride * static_cast<std::size_t>(thread);
            solveFamily(s, lines, first, last, stiffness, xpbd, alphaTilde, scratch.lineNormal.data() + slice,
                        scratch.lineUpper.data() + slice, scratch.lineSolution.data() + slice);
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
