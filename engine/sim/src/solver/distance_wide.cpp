// A batch's distance projections four at a time: this file alone of the position model is built
// for AVX (engine/sim/CMakeLists.txt), and position_model.cpp calls it only where the CPU has AVX.
// It uses no library template and no GLM function: code built for AVX must not be what the linker
// picks for a function the portable code calls too.
#include "solver/distance_wide.hpp"

#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace drape::sim::position {

#if defined(__AVX__)
namespace {

// x, y and z of the particles at index[0..3], a lane each.
struct Xyz {
  __m256d x, y, z;
};

Xyz load(const double* position, const std::uint32_t* index) {
  const double* p0 = position + 3 * std::size_t{index[0]};
  const double* p1 = position + 3 * std::size_t{index[1]};
  const double* p2 = position + 3 * std::size_t{index[2]};
  const double* p3 = position + 3 * std::size_t{index[3]};
  // [x0 y0 | x2 y2] and [x1 y1 | x3 y3]
  const __m256d even = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p0)), _mm_loadu_pd(p2), 1);
  const __m256d odd = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p1)), _mm_loadu_pd(p3), 1);
  return {_mm256_unpacklo_pd(even, odd), _mm256_unpackhi_pd(even, odd), _mm256_set_pd(p3[2], p2[2], p1[2], p0[2])};
}

void store(double* position, const std::uint32_t* index, const Xyz& v) {
  const __m256d even = _mm256_unpacklo_pd(v.x, v.y);  // [x0 y0 | x2 y2]
  const __m256d odd = _mm256_unpackhi_pd(v.x, v.y);   // [x1 y1 | x3 y3]
  double* p0 = position + 3 * std::size_t{index[0]};
  double* p1 = position + 3 * std::size_t{index[1]};
  double* p2 = position + 3 * std::size_t{index[2]};
  double* p3 = position + 3 * std::size_t{index[3]};
  _mm_storeu_pd(p0, _mm256_castpd256_pd128(even));
  _mm_storeu_pd(p1, _mm256_castpd256_pd128(odd));
  _mm_storeu_pd(p2, _mm256_extractf128_pd(even, 1));
  _mm_storeu_pd(p3, _mm256_extractf128_pd(odd, 1));
  const __m128d zLow = _mm256_castpd256_pd128(v.z), zHigh = _mm256_extractf128_pd(v.z, 1);
  _mm_storel_pd(p0 + 2, zLow);
  _mm_storeh_pd(p1 + 2, zLow);
  _mm_storel_pd(p2 + 2, zHigh);
  _mm_storeh_pd(p3 + 2, zHigh);
}

}  // namespace

std::size_t projectBatchWide(double* position, const double* inverseMass, const DistanceConstraint* constraints,
                             std::size_t begin, std::size_t end, double stiffness) {
  const __m256d zero = _mm256_setzero_pd(), tiny = _mm256_set1_pd(1e-20), s = _mm256_set1_pd(stiffness);
  std::size_t k = begin;
  for (; k + 4 <= end; k += 4) {
    const DistanceConstraint* c = constraints + k;
    const std::uint32_t a[4] = {c[0].a, c[1].a, c[2].a, c[3].a};
    const std::uint32_t b[4] = {c[0].b, c[1].b, c[2].b, c[3].b};
    const __m256d wa = _mm256_set_pd(inverseMass[a[3]], inverseMass[a[2]], inverseMass[a[1]], inverseMass[a[0]]);
    const __m256d wb = _mm256_set_pd(inverseMass[b[3]], inverseMass[b[2]], inverseMass[b[1]], inverseMass[b[0]]);
    const __m256d rest = _mm256_set_pd(c[3].restLength, c[2].restLength, c[1].restLength, c[0].restLength);
    const Xyz xa = load(position, a), xb = load(position, b);
    // As projectDistance, operation for operation: the lanes it would return early from (nothing
    // to move, or coincident particles) keep their positions, bit for bit.
    const __m256d wSum = _mm256_add_pd(wa, wb);
    const __m256d dx = _mm256_sub_pd(xb.x, xa.x), dy = _mm256_sub_pd(xb.y, xa.y), dz = _mm256_sub_pd(xb.z, xa.z);
    const __m256d length2 =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
    const __m256d moves =
        _mm256_and_pd(_mm256_cmp_pd(wSum, zero, _CMP_NEQ_UQ), _mm256_cmp_pd(length2, tiny, _CMP_GT_OQ));
    if (_mm256_movemask_pd(moves) == 0) continue;
    const __m256d length = _mm256_sqrt_pd(length2);
    const __m256d factor = _mm256_div_pd(_mm256_mul_pd(s, _mm256_sub_pd(length, rest)), _mm256_mul_pd(length, wSum));
    const __m256d cx = _mm256_mul_pd(dx, factor), cy = _mm256_mul_pd(dy, factor), cz = _mm256_mul_pd(dz, factor);
    store(position, a,
          {_mm256_blendv_pd(xa.x, _mm256_add_pd(xa.x, _mm256_mul_pd(wa, cx)), moves),
           _mm256_blendv_pd(xa.y, _mm256_add_pd(xa.y, _mm256_mul_pd(wa, cy)), moves),
           _mm256_blendv_pd(xa.z, _mm256_add_pd(xa.z, _mm256_mul_pd(wa, cz)), moves)});
    store(position, b,
          {_mm256_blendv_pd(xb.x, _mm256_sub_pd(xb.x, _mm256_mul_pd(wb, cx)), moves),
           _mm256_blendv_pd(xb.y, _mm256_sub_pd(xb.y, _mm256_mul_pd(wb, cy)), moves),
           _mm256_blendv_pd(xb.z, _mm256_sub_pd(xb.z, _mm256_mul_pd(wb, cz)), moves)});
  }
  return k;
}
#else
// Not built for AVX (not an x86 machine): never called, as the CPU check says no.
std::size_t projectBatchWide(double*, const double*, const DistanceConstraint*, std::size_t begin, std::size_t,
                             double) {
  return begin;
}
#endif

}  // namespace drape::sim::position
