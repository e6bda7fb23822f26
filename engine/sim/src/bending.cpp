#include "bending.hpp"

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
  return -(Real(b.k[1]) + Real(b.k[2]) + Real(b.k[3]) + Real(b.k[4]));
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
      for (int j = 0; j < 5; ++j) {
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
        // touches are in stencil order: touches[a].stencil >= touches[b].stencil
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
    for (int j = 1; j < 5; ++j) C += Real(b.k[j]) * (x[b.v[j]] - centre);
    y[i] = -(C + alphaTilde * lambda[i]);
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
    lambda[i] += y[i];
    for (int j = 0; j < 5; ++j) x[b.v[j]] += (w[b.v[j]] * weightOf(b, j)) * y[i];
  }
}

}  // namespace drape::sim::bending
