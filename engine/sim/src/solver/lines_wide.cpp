// The full Newton line step's elimination eight lines at a time, and the gather and scatter of
// eight neighbouring lines: this file alone is built for AVX (engine/sim/CMakeLists.txt), and
// lines.cpp calls it only where the CPU has AVX. No GLM: positions are read as x, y, z doubles.
#include "solver/lines_wide.hpp"

#include "solver/stiff_lanes.hpp"

namespace drape::sim::lines {

void solveStiffLanesWide(SolverScratch::StiffRows* rows, std::size_t n, const float* alphaTilde) {
  solveStiffLanes<Wide>(rows, n, load<Wide>(alphaTilde));
}

#if defined(__AVX__)
namespace {

// Four consecutive particles' x, y, z (12 doubles from p) as x[4], y[4], z[4]: p holds
// a = [x0 y0 z0 x1], b = [y1 z1 x2 y2], c = [z2 x3 y3 z3].
struct Soa {
  __m256d x, y, z;
};
Soa toSoa(__m256d a, __m256d b, __m256d c) {
  const __m256d p = _mm256_blend_pd(a, b, 0b1100);       // x0 y0 x2 y2
  const __m256d q = _mm256_permute2f128_pd(a, c, 0x21);  // z0 x1 z2 x3
  const __m256d r = _mm256_blend_pd(b, c, 0b1100);       // y1 z1 y3 z3
  return {_mm256_blend_pd(p, q, 0b1010), _mm256_shuffle_pd(p, r, 0b0101), _mm256_blend_pd(q, r, 0b1010)};
}
// ... and back: a, b, c as above.
void toAos(const Soa& v, __m256d& a, __m256d& b, __m256d& c) {
  const __m256d p = _mm256_unpacklo_pd(v.x, v.y);         // x0 y0 x2 y2
  const __m256d q = _mm256_shuffle_pd(v.z, v.x, 0b1010);  // z0 x1 z2 x3
  const __m256d r = _mm256_unpackhi_pd(v.y, v.z);         // y1 z1 y3 z3
  a = _mm256_permute2f128_pd(p, q, 0x20);
  b = _mm256_blend_pd(r, p, 0b1100);
  c = _mm256_permute2f128_pd(q, r, 0x31);
}
// Eight doubles (two registers) as eight floats, rounded as static_cast<float> rounds.
__m256 toFloats(__m256d low, __m256d high) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm256_cvtpd_ps(low)), _mm256_cvtpd_ps(high), 1);
}
// 1.0 where a comparison holds, else 0.0.
__m256d ones(__m256d holds) { return _mm256_and_pd(holds, _mm256_set1_pd(1.0)); }
// Particle k of a line whose link k joins particle k (a) to k + 1 (b).
std::size_t particleOf(const DistanceConstraint* link, std::size_t k) { return k == 0 ? link[0].a : link[k - 1].b; }

}  // namespace

void gatherConsecutiveWide(SolverScratch::StiffRows* rows, std::size_t n, const double* position,
                           const double* inverseMass, const float* mass, const DistanceConstraint* first,
                           const DistanceConstraint* const* lineLinks, const double* const* lambda,
                           const float* const* tension, const double* perUnitMass, double alphaTilde) {
  const std::size_t links = n - 1;
  const __m256d zero = _mm256_setzero_pd(), alpha = _mm256_set1_pd(alphaTilde);
  const __m256d scaleLow = _mm256_loadu_pd(perUnitMass), scaleHigh = _mm256_loadu_pd(perUnitMass + 4);
  for (std::size_t k = 0; k < n; ++k) {
    SolverScratch::StiffRows& r = rows[k];
    const std::size_t at = particleOf(first, k);
    const __m256d wLow = _mm256_loadu_pd(inverseMass + at), wHigh = _mm256_loadu_pd(inverseMass + at + 4);
    // (StiffRows: v[0] and v[1] hold the particle's mass and whether it moves until the solve.)
    _mm256_storeu_ps(r.v[0], toFloats(_mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(mass + at)), scaleLow),
                                      _mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(mass + at + 4)), scaleHigh)));
    _mm256_storeu_ps(
        r.v[1], toFloats(ones(_mm256_cmp_pd(wLow, zero, _CMP_GT_OQ)), ones(_mm256_cmp_pd(wHigh, zero, _CMP_GT_OQ))));
    if (k == links) {
      float* const none[] = {r.nx, r.ny, r.nz, r.yl, r.g, r.schur};  // no link after the last particle
      for (float* lanes : none) _mm256_storeu_ps(lanes, _mm256_setzero_ps());
      continue;
    }
    if (k + 4 < n) {  // the rows ahead: particles a row apart are a lattice's width apart in memory
      const std::size_t later = first[k + 3].b;
      const double* ahead = position + 3 * later;
      _mm_prefetch(reinterpret_cast<const char*>(ahead), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(ahead + 8), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(ahead + 16), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(inverseMass + later), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(mass + later), _MM_HINT_T0);
    }
    const std::size_t next = first[k].b;
    const double* from = position + 3 * at;
    const double* to = position + 3 * next;
    // The links' differences, to - from, four particles at a time.
    Soa d[2];
    for (int half = 0; half < 2; ++half) {
      const double* f = from + 12 * half;
      const double* t = to + 12 * half;
      d[half] = toSoa(_mm256_sub_pd(_mm256_loadu_pd(t), _mm256_loadu_pd(f)),
                      _mm256_sub_pd(_mm256_loadu_pd(t + 4), _mm256_loadu_pd(f + 4)),
                      _mm256_sub_pd(_mm256_loadu_pd(t + 8), _mm256_loadu_pd(f + 8)));
    }
    _mm256_storeu_ps(r.nx, toFloats(d[0].x, d[1].x));
    _mm256_storeu_ps(r.ny, toFloats(d[0].y, d[1].y));
    _mm256_storeu_ps(r.nz, toFloats(d[0].z, d[1].z));
    const __m256d toWLow = _mm256_loadu_pd(inverseMass + next), toWHigh = _mm256_loadu_pd(inverseMass + next + 4);
    _mm256_storeu_ps(
        r.schur, toFloats(ones(_mm256_cmp_pd(_mm256_add_pd(_mm256_add_pd(wLow, toWLow), alpha), zero, _CMP_GT_OQ)),
                          ones(_mm256_cmp_pd(_mm256_add_pd(_mm256_add_pd(wHigh, toWHigh), alpha), zero, _CMP_GT_OQ))));
    // Each line's own rest length, multiplier and tension, as the scalar gather takes them.
    for (std::size_t g = 0; g < 8; ++g) {
      r.yl[g] = static_cast<float>(lineLinks[g][k].restLength - (lambda[g] ? alphaTilde * lambda[g][k] : 0.0));
      const double minus = -static_cast<double>(tension[g][k]);
      r.g[g] = static_cast<float>((minus < 0.0 ? 0.0 : minus) * perUnitMass[g]);  // std::max(minus, 0.0)
    }
  }
}

void scatterConsecutiveWide(const SolverScratch::StiffRows* rows, std::size_t n, double* position,
                            const double* inverseMass, const DistanceConstraint* first, double stiffness) {
  const __m256d scale = _mm256_set1_pd(stiffness);
  const __m256d zero = _mm256_setzero_pd();
  for (std::size_t j = 0; j < n; ++j) {
    const SolverScratch::StiffRows& r = rows[j];
    const std::size_t at = particleOf(first, j);
    // Which particles move: inverse mass above 0, as the gather found them.
    const __m256 moving = toFloats(ones(_mm256_cmp_pd(_mm256_loadu_pd(inverseMass + at), zero, _CMP_GT_OQ)),
                                   ones(_mm256_cmp_pd(_mm256_loadu_pd(inverseMass + at + 4), zero, _CMP_GT_OQ)));
    const __m256 moves = _mm256_cmp_ps(moving, _mm256_setzero_ps(), _CMP_NEQ_UQ);  // != 0.0f
    double* x = position + 3 * at;
    if (j + 4 < n) {
      const double* ahead = position + 3 * std::size_t{first[j + 3].b};
      _mm_prefetch(reinterpret_cast<const char*>(ahead), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(ahead + 8), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(ahead + 16), _MM_HINT_T0);
    }
    for (int half = 0; half < 2; ++half) {
      const auto lanes = [&](const float* a) { return _mm256_cvtps_pd(_mm_loadu_ps(a + 4 * half)); };
      const Soa move{_mm256_mul_pd(lanes(r.yx[0]), scale), _mm256_mul_pd(lanes(r.yx[1]), scale),
                     _mm256_mul_pd(lanes(r.yx[2]), scale)};
      // Which of the four particles move, as a mask of doubles laid out as their coordinates are.
      const __m128 movesHalf = half == 0 ? _mm256_castps256_ps128(moves) : _mm256_extractf128_ps(moves, 1);
      const __m256d m = _mm256_castsi256_pd(_mm256_insertf128_si256(
          _mm256_castsi128_si256(_mm_unpacklo_epi32(_mm_castps_si128(movesHalf), _mm_castps_si128(movesHalf))),
          _mm_unpackhi_epi32(_mm_castps_si128(movesHalf), _mm_castps_si128(movesHalf)), 1));
      __m256d ma, mb, mc, da, db, dc;
      toAos({m, m, m}, ma, mb, mc);
      toAos(move, da, db, dc);
      double* p = x + 12 * half;
      const __m256d a = _mm256_loadu_pd(p), b = _mm256_loadu_pd(p + 4), c = _mm256_loadu_pd(p + 8);
      _mm256_storeu_pd(p, _mm256_blendv_pd(a, _mm256_add_pd(a, da), ma));
      _mm256_storeu_pd(p + 4, _mm256_blendv_pd(b, _mm256_add_pd(b, db), mb));
      _mm256_storeu_pd(p + 8, _mm256_blendv_pd(c, _mm256_add_pd(c, dc), mc));
    }
  }
}
#else
// Not built for AVX (not an x86 machine): never called, as the CPU check says no.
void gatherConsecutiveWide(SolverScratch::StiffRows*, std::size_t, const double*, const double*, const float*,
                           const DistanceConstraint*, const DistanceConstraint* const*, const double* const*,
                           const float* const*, const double*, double) {}
void scatterConsecutiveWide(const SolverScratch::StiffRows*, std::size_t, double*, const double*,
                            const DistanceConstraint*, double) {}
#endif

}  // namespace drape::sim::lines
