// The elimination at the heart of the full Newton line step (lines.cpp, solveStiffLines), for the
// lines gathered side by side into StiffRows: a template over the vector of floats that holds one
// lane per line, so that the same source runs four lines to an SSE register (lines.cpp, the
// portable build) and eight to an AVX one (lines_wide.cpp, built for AVX and called only where the
// CPU has it). Each lane's arithmetic is the same whatever the width: IEEE operations in the same
// order, nothing fused (the project builds with -ffp-contract=off), so both give the same bits.
//
// Included by those two files alone. Everything here has internal linkage and uses no library
// template: code built for AVX must not be what the linker picks for a function the portable code
// calls too.
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "drape/sim/state.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::lines {
namespace {

using StiffRow = SolverScratch::StiffRows;
using Narrow = float __attribute__((vector_size(16)));  // 4 lanes
using Wide = float __attribute__((vector_size(32)));    // 8 lanes

template <class V>
struct MaskOf;
template <>
struct MaskOf<Narrow> {
  using type = std::int32_t __attribute__((vector_size(16)));
};
template <>
struct MaskOf<Wide> {
  using type = std::int32_t __attribute__((vector_size(32)));
};
template <class V>
using Mask = typename MaskOf<V>::type;

template <class V>
struct Lane3 {
  V x, y, z;
};
template <class V>
struct LaneSym3 {
  V xx, yy, zz, xy, xz, yz;
};

// The first lanes of a row's quantity (as many as V holds).
template <class V>
V load(const float* a) {
  V v;
  __builtin_memcpy(&v, a, sizeof v);
  return v;
}
template <class V>
void keep(float* a, V v) {
  __builtin_memcpy(a, &v, sizeof v);
}
template <class V>
Lane3<V> load3(const StiffRow::Lanes* a) {
  return {load<V>(a[0]), load<V>(a[1]), load<V>(a[2])};
}
template <class V>
void keep3(StiffRow::Lanes* a, const Lane3<V>& v) {
  keep(a[0], v.x);
  keep(a[1], v.y);
  keep(a[2], v.z);
}
template <class V>
LaneSym3<V> loadSym(const StiffRow::Lanes* a) {
  return {load<V>(a[0]), load<V>(a[1]), load<V>(a[2]), load<V>(a[3]), load<V>(a[4]), load<V>(a[5])};
}
template <class V>
void keepSym(StiffRow::Lanes* a, const LaneSym3<V>& m) {
  keep(a[0], m.xx);
  keep(a[1], m.yy);
  keep(a[2], m.zz);
  keep(a[3], m.xy);
  keep(a[4], m.xz);
  keep(a[5], m.yz);
}
template <class V>
Lane3<V> operator+(const Lane3<V>& a, const Lane3<V>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
Lane3<V> operator-(const Lane3<V>& a, const Lane3<V>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class V>
Lane3<V> operator*(const Lane3<V>& a, V s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class V>
V dot(const Lane3<V>& a, const Lane3<V>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
// 1 in the lanes a comparison holds in, else 0.
template <class V>
V ones(Mask<V> holds) {
  const V one = V{} + 1.0f;
  return __builtin_bit_cast(V, holds & __builtin_bit_cast(Mask<V>, one));
}
// a where the comparison holds, else b.
template <class V>
V select(Mask<V> holds, V a, V b) {
  return __builtin_bit_cast(V, (holds & __builtin_bit_cast(Mask<V>, a)) | (~holds & __builtin_bit_cast(Mask<V>, b)));
}
template <class V>
V squareRoot(V a) {
#if defined(__AVX__)
  if constexpr (sizeof(V) == 32) return _mm256_sqrt_ps(a);
#endif
#if defined(__SSE__)
  if constexpr (sizeof(V) == 16) return _mm_sqrt_ps(a);
#endif
  for (std::size_t lane = 0; lane < sizeof(V) / sizeof(float); ++lane) a[lane] = __builtin_sqrtf(a[lane]);
  return a;
}
template <class V>
Lane3<V> operator*(const LaneSym3<V>& m, const Lane3<V>& u) {
  return {m.xx * u.x + m.xy * u.y + m.xz * u.z, m.xy * u.x + m.yy * u.y + m.yz * u.z,
          m.xz * u.x + m.yz * u.y + m.zz * u.z};
}
template <class V>
LaneSym3<V> operator+(const LaneSym3<V>& a, const LaneSym3<V>& b) {
  return {a.xx + b.xx, a.yy + b.yy, a.zz + b.zz, a.xy + b.xy, a.xz + b.xz, a.yz + b.yz};
}
template <class V>
LaneSym3<V> operator*(const LaneSym3<V>& a, V s) {
  return {a.xx * s, a.yy * s, a.zz * s, a.xy * s, a.xz * s, a.yz * s};
}
// s (I - u u^T)
template <class V>
LaneSym3<V> across(const Lane3<V>& u, V s) {
  return {(1.0f - u.x * u.x) * s, (1.0f - u.y * u.y) * s, (1.0f - u.z * u.z) * s,
          -u.x * u.y * s,         -u.x * u.z * s,         -u.y * u.z * s};
}
template <class V>
LaneSym3<V> outer(const Lane3<V>& u) {
  return {u.x * u.x, u.y * u.y, u.z * u.z, u.x * u.y, u.x * u.z, u.y * u.z};
}
// u v^T + v u^T
template <class V>
LaneSym3<V> outer(const Lane3<V>& u, const Lane3<V>& v) {
  return {2.0f * u.x * v.x,      2.0f * u.y * v.y,      2.0f * u.z * v.z,
          u.x * v.y + u.y * v.x, u.x * v.z + u.z * v.x, u.y * v.z + u.z * v.y};
}
template <class V>
[[gnu::always_inline]] inline LaneSym3<V> inverse(const LaneSym3<V>& a) {
  const V cxx = a.yy * a.zz - a.yz * a.yz, cxy = a.xz * a.yz - a.xy * a.zz, cxz = a.xy * a.yz - a.xz * a.yy;
  const V inv = 1.0f / (a.xx * cxx + a.xy * cxy + a.xz * cxz);
  return {cxx * inv, (a.xx * a.zz - a.xz * a.xz) * inv, (a.xx * a.yy - a.xy * a.xy) * inv, cxy * inv,
          cxz * inv, (a.xy * a.xz - a.xx * a.yz) * inv};
}

// A link as the solve uses it: its direction, geometric stiffness g, value C + alpha~ lambda, and 1
// if the solve corrects it (else 0).
template <class V>
struct Link {
  Lane3<V> unit;
  V pull, rhs, live;
};

// Link j from what solveStiffLines gathered into row j: the difference of its particles (in nx, ny,
// nz), its rest length less alpha~ lambda (in yl), its tension over the unit mass (g) and 1 if
// anything can move it (in schur). A link with no direction is dead. Keeps in the row what the back
// substitution reads again: the direction and g.
template <class V>
Link<V> normalise(StiffRow& r) {
  const Lane3<V> d{load<V>(r.nx), load<V>(r.ny), load<V>(r.nz)};
  const V length2 = dot(d, d);
  const V live = load<V>(r.schur) * ones<V>(length2 > 1e-20f);
  const V length = squareRoot(length2 * live + (1.0f - live));  // 1 where dead
  const V inverseLength = live / length;
  const Link<V> link{d * inverseLength, load<V>(r.g) * inverseLength, (length - load<V>(r.yl)) * live, live};
  keep(r.nx, link.unit.x);
  keep(r.ny, link.unit.y);
  keep(r.nz, link.unit.z);
  keep(r.g, link.pull);
  return link;
}

// The elimination of solveStiffLines for the first lanes (as many as V holds) of rows[0, n),
// gathered (the particle's mass in v[0], 1 if it moves in v[1]; StiffRows); alphaTilde per lane. On
// return each row's yx holds its particle's move and yl its link-before's multiplier.
template <class V>
void solveStiffLanes(StiffRow* rows, std::size_t n, V alphaTilde) {
  const auto direction = [](const StiffRow& r) { return Lane3<V>{load<V>(r.nx), load<V>(r.ny), load<V>(r.nz)}; };
  const V zero{}, one = zero + 1.0f;
  // Forward. P is the last node's (S^-1)_xx, zx its (S^-1 y)_x: what it passes on through the link.
  LaneSym3<V> P;
  Lane3<V> zx{zero, zero, zero};
  Link<V> next = normalise<V>(rows[0]);
  LaneSym3<V> nextAcross = across(next.unit, next.pull);  // G of the link after the node
  {
    StiffRow& r = rows[0];
    const V m = load<V>(r.v[0]);
    const LaneSym3<V> inverseA = inverse(LaneSym3<V>{m, m, m, zero, zero, zero} + nextAcross) * load<V>(r.v[1]);
    keepSym(r.inverse, inverseA);
    P = inverseA;
    keep3(r.v, zx);
    keep3(r.b, zx);
    keep3(r.yx, zx);
    keep(r.schur, one);
    keep(r.yl, zero);
  }
  for (std::size_t j = 1; j < n; ++j) {
    const Link<V> link = next;  // joins particle j - 1 to j
    const LaneSym3<V> linkAcross = nextAcross;
    StiffRow& r = rows[j];
    next = normalise<V>(r);
    nextAcross = across(next.unit, next.pull);
    const Lane3<V> unit = link.unit;
    const V pull = link.pull, live = link.live;
    const Lane3<V> Pn = P * unit;
    const V nPn = dot(unit, Pn);
    const Lane3<V> b = (Pn - unit * nPn) * pull - unit;
    const V c = live * (-alphaTilde - nPn) + (1.0f - live);  // a dead link: the row of the identity
    const V nz = dot(unit, zx);
    const Lane3<V> yx = (zx - unit * nz) * pull;
    V yl = live * (link.rhs - nz);
    // A = m I + G_{j-1} + G_j - G_{j-1} P G_{j-1}
    const V m = load<V>(r.v[0]);
    const LaneSym3<V> A = LaneSym3<V>{m, m, m, zero, zero, zero} + linkAcross + nextAcross +
                          (P + outer(unit, Pn) * -one + outer(unit) * nPn) * (-pull * pull);
    const LaneSym3<V> inverseA = inverse(A) * load<V>(r.v[1]);
    const Lane3<V> v = inverseA * b;
    V schur = c - dot(b, v);
    // Both particles held (or a zero pivot): the link cannot be corrected.
    const Mask<V> correctable = (schur > 0.0f) | (schur < 0.0f);
    schur = select(correctable, schur, one);
    yl = select(correctable, yl, zero);
    schur = 1.0f / schur;
    const Lane3<V> t = inverseA * yx;
    const V zl = (yl - dot(b, t)) * schur;
    zx = t - v * zl;
    P = inverseA + outer(v) * schur;
    keepSym(r.inverse, inverseA);
    keep3(r.v, v);
    keep3(r.b, b);
    keep3(r.yx, yx);
    keep(r.schur, schur);
    keep(r.yl, yl);
  }

  // Back: particle j's move and link j - 1's multiplier, from node j + 1's.
  Lane3<V> ux{zero, zero, zero};
  V ul = zero;
  for (std::size_t j = n; j-- > 0;) {
    StiffRow& r = rows[j];
    Lane3<V> px = load3<V>(r.yx);
    if (j + 1 < n) {  // minus link j's coupling to node j + 1
      const Lane3<V> unit = direction(r);
      px = px + (ux - unit * dot(unit, ux)) * load<V>(r.g) - unit * ul;
    }
    const Lane3<V> t = loadSym<V>(r.inverse) * px;
    ul = j > 0 ? (load<V>(r.yl) - dot(load3<V>(r.b), t)) * load<V>(r.schur) : zero;
    ux = t - load3<V>(r.v) * ul;
    keep3(r.yx, ux);
    keep(r.yl, ul);
  }
}

}  // namespace
}  // namespace drape::sim::lines
