#include "solver/bending.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace drape::sim::bending {

namespace {

// Of the stencils that touch each particle: which, and with what weight.
struct Touch {
  std::uint32_t stencil;
  Real k;
};

// Stencil b's weight on its j-th particle, in double: the centre's the exact negative of the others'
// sum (its stored single-precision k[0] differs from that by rounding), so that the matrix and
// the update are the constraint the projection measures, C = sum_{j>0} k_j (x_j - x_0).
Real weightOf(const BendStencil& b, int j) {
  if (j > 0) return Real(b.k[j]);
  Real sum = 0.0;
  for (int i = 1, used = stencilSize(b); i < used; ++i) sum += Real(b.k[i]);
  return -sum;
}

// Reverse Cuthill-McKee: the stencils renumbered so that those sharing a particle lie close in the
// new order (a narrow band whatever order the mesh lists them in: a drawn cloth lists its border
// particles after its inside ones, which gave a band as wide as the cloth). A breadth-first walk
// from the far end of each connected part (a node the walk from its first stencil reaches last),
// neighbours in order of their degree, then reversed. rank[stencil] = its place.
std::vector<std::uint32_t> reverseCuthillMcKee(const std::vector<std::vector<std::uint32_t>>& adjacent) {
  const std::size_t n = adjacent.size();
  constexpr std::uint32_t kNone = ~0u;
  std::vector<std::uint32_t> order, seen(n, kNone);
  order.reserve(n);
  std::vector<std::uint32_t> next;
  const auto walk = [&](std::uint32_t from, std::uint32_t mark, std::vector<std::uint32_t>& out) {
    out.clear();
    out.push_back(from);
    seen[from] = mark;
    for (std::size_t head = 0; head < out.size(); ++head) {
      next.clear();
      for (const std::uint32_t j : adjacent[out[head]]) {
        if (seen[j] != mark) next.push_back(j);
      }
      std::sort(next.begin(), next.end(), [&](std::uint32_t a, std::uint32_t b) {
        return adjacent[a].size() != adjacent[b].size() ? adjacent[a].size() < adjacent[b].size() : a < b;
      });
      for (const std::uint32_t j : next) {
        if (seen[j] == mark) continue;
        seen[j] = mark;
        out.push_back(j);
      }
    }
  };
  std::vector<std::uint32_t> part;
  for (std::uint32_t first = 0; first < n; ++first) {
    if (seen[first] != kNone) continue;
    walk(first, kNone - 1, part);  // to find the far end
    walk(part.back(), kNone - 2, part);
    for (const std::uint32_t i : part) seen[i] = 0;  // placed
    order.insert(order.end(), part.rbegin(), part.rend());
  }
  std::vector<std::uint32_t> rank(n);
  for (std::uint32_t k = 0; k < n; ++k) rank[order[k]] = k;
  return rank;
}

}  // namespace

bool prepare(BendingFactor& factor, const std::vector<BendStencil>& stencils, const std::vector<Real>& inverseMass,
             Real alphaTilde) {
  if (factor.alphaTilde == alphaTilde && factor.stencils == stencils && factor.inverseMass == inverseMass) {
    return factor.usable;
  }
  factor.stencils = stencils;
  factor.inverseMass = inverseMass;
  factor.alphaTilde = alphaTilde;
  factor.usable = false;
  factor.lower.clear();
  const std::size_t n = stencils.size(), particles = inverseMass.size();
  if (n == 0) return false;
  // Each free particle's stencils, by particle (counting sort), in stencil order.
  std::vector<std::uint32_t> start(particles + 1, 0);
  const auto each = [&](auto&& f) {
    for (std::uint32_t i = 0; i < n; ++i) {
      for (int j = 0; j < kBendStencilSize; ++j) {
        const ParticleIndex p = stencils[i].v[j];
        const Real k = weightOf(stencils[i], j);
        if (k != 0.0 && inverseMass[p] != 0.0) f(p, Touch{i, k});
      }
    }
  };
  each([&](ParticleIndex p, Touch) { ++start[p + 1]; });
  for (std::size_t p = 0; p < particles; ++p) start[p + 1] += start[p];
  std::vector<Touch> touches(start[particles]);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  each([&](ParticleIndex p, Touch t) { touches[fill[p]++] = t; });
  // Stencils that share a free particle are neighbours; numbered afresh so that neighbours lie
  // close (touches then name stencils by their new number, each particle's in that order).
  std::vector<std::vector<std::uint32_t>> adjacent(n);
  for (std::size_t p = 0; p < particles; ++p) {
    for (std::uint32_t a = start[p]; a < start[p + 1]; ++a) {
      for (std::uint32_t b = start[p]; b < start[p + 1]; ++b) {
        if (touches[a].stencil != touches[b].stencil) adjacent[touches[a].stencil].push_back(touches[b].stencil);
      }
    }
  }
  for (std::vector<std::uint32_t>& list : adjacent) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  factor.rank = reverseCuthillMcKee(adjacent);
  for (Touch& t : touches) t.stencil = factor.rank[t.stencil];
  for (std::size_t p = 0; p < particles; ++p) {
    std::sort(touches.begin() + start[p], touches.begin() + start[p + 1],
              [](const Touch& a, const Touch& b) { return a.stencil < b.stencil; });
  }
  // The half-bandwidth: the farthest apart two stencils that share a particle are.
  std::size_t band = 0;
  for (std::size_t p = 0; p < particles; ++p) {
    if (start[p + 1] > start[p])
      band = std::max<std::size_t>(band, touches[start[p + 1] - 1].stencil - touches[start[p]].stencil);
  }
  if (static_cast<double>(n) * static_cast<double>(band + 1) * static_cast<double>(band + 1) > kMaxFactorWork) {
    return false;
  }
  const std::size_t width = band + 1;
  std::vector<Real>& L = factor.lower;
  L.assign(n * width, 0.0);
  const auto at = [&](std::size_t row, std::size_t column) -> Real& { return L[row * width + column + band - row]; };
  // S = G W G^T + alpha~ I, its lower band.
  for (std::size_t i = 0; i < n; ++i) at(i, i) = alphaTilde;
  for (std::size_t p = 0; p < particles; ++p) {
    const Real w = inverseMass[p];
    for (std::uint32_t a = start[p]; a < start[p + 1]; ++a) {
      for (std::uint32_t b = start[p]; b <= a; ++b) {
        // touches are in the new order: touches[a].stencil >= touches[b].stencil
        at(touches[a].stencil, touches[b].stencil) += w * touches[a].k * touches[b].k;
      }
    }
  }
  // Cholesky in place: S = L L^T.
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t first = i > band ? i - band : 0;
    for (std::size_t j = first; j <= i; ++j) {
      Real sum = at(i, j);
      const Real* li = &at(i, first);
      const Real* lj = &at(j, first);
      for (std::size_t k = 0; k + first < j; ++k) sum -= li[k] * lj[k];
      if (j < i) {
        at(i, j) = sum / at(j, j);
      } else {
        if (!(sum > 0.0) || !std::isfinite(sum)) {
          L.clear();
          return false;
        }
        at(i, i) = std::sqrt(sum);
      }
    }
  }
  factor.band = band;
  factor.work.resize(n);
  factor.usable = true;
  return true;
}

void project(BendingFactor& factor, ParticleState& s, const std::vector<BendStencil>& stencils,
             std::vector<Vec3>& lambda, Real alphaTilde) {
  const std::size_t n = stencils.size(), band = factor.band, width = band + 1;
  Vec3* x = s.position.data();
  const Real* w = s.inverseMass.data();
  const Real* L = factor.lower.data();
  std::vector<Vec3>& y = factor.work;
  for (std::size_t i = 0; i < n; ++i) {
    const BendStencil& b = stencils[i];
    Vec3 C{0.0};
    const Vec3 centre = x[b.v[0]];
    for (int j = 1, used = stencilSize(b); j < used; ++j) C += Real(b.k[j]) * (x[b.v[j]] - centre);
    y[factor.rank[i]] = -(C + alphaTilde * lambda[i]);
  }
  // L y' = y, then L^T dlambda = y', in place.
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t first = i > band ? i - band : 0;
    const Real* row = L + i * width + band - i;  // row[k] = L(i, k)
    Vec3 sum = y[i];
    for (std::size_t k = first; k < i; ++k) sum -= row[k] * y[k];
    y[i] = sum / row[i];
  }
  for (std::size_t i = n; i-- > 0;) {
    const std::size_t first = i > band ? i - band : 0;
    const Real* row = L + i * width + band - i;
    y[i] /= row[i];
    for (std::size_t k = first; k < i; ++k) y[k] -= row[k] * y[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    const BendStencil& b = stencils[i];
    const Vec3 delta = y[factor.rank[i]];
    lambda[i] += delta;
    for (int j = 0, used = stencilSize(b); j < used; ++j) x[b.v[j]] += (w[b.v[j]] * weightOf(b, j)) * delta;
  }
}

}  // namespace drape::sim::bending
