// WatertightTest::intersect on double lanes (AVX-512), two ways: lanes over
// the 16 rays of a packet against one triangle (WatertightLanes, the doubles
// in two halves of 8), for packets whose rays share the axis permutation
// (kx, ky, kz): camera rays and their shadow and mirror rays nearly always
// do; and lanes over up to 8 (or 4) triangles of a leaf against one ray
// (watertight_leaf<8>, watertight_leaf<4>), loaded a row of the leaf's verts
// block at a time. Lane by lane the operations are the scalar test's, in the
// same order and precision (the float differences, the shear and edge
// functions in double with exact products, the fused t sum, one division),
// so a lane hits exactly when the scalar test says so, with the same t, u, v.
#pragma once

#if defined(__AVX512F__)
#include <immintrin.h>

#include <cstdint>

#include "bvh/intersect/ray_triangle.h"
#include "bvh/layout/leaf_triangles.h"
#include "core/force_inline.h"

namespace hprt {

namespace detail {

// The vectors and operations of the lane test at W lanes: W floats, W
// doubles, a W-bit mask. Conversions go through their mask variants: the
// plain 512-bit ones pass an undefined operand that g++ 12 reports as
// maybe-uninitialized.
template <int W>
struct Lanes;

template <>
struct Lanes<8> {
  using F = __m256;
  using D = __m512d;
  static HPRT_FORCE_INLINE D wide(F f) {
    return _mm512_mask_cvtps_pd(_mm512_setzero_pd(), 0xFF, f);
  }
  static HPRT_FORCE_INLINE F narrow(D d) {
    return _mm512_mask_cvtpd_ps(_mm256_setzero_ps(), 0xFF, d);
  }
  static HPRT_FORCE_INLINE D set(double x) { return _mm512_set1_pd(x); }
  static HPRT_FORCE_INLINE F setf(float x) { return _mm256_set1_ps(x); }
  static HPRT_FORCE_INLINE F subf(F a, F b) { return _mm256_sub_ps(a, b); }
  static HPRT_FORCE_INLINE D add(D a, D b) { return _mm512_add_pd(a, b); }
  static HPRT_FORCE_INLINE D mul(D a, D b) { return _mm512_mul_pd(a, b); }
  static HPRT_FORCE_INLINE D div(D a, D b) { return _mm512_div_pd(a, b); }
  static HPRT_FORCE_INLINE D fmadd(D a, D b, D c) { return _mm512_fmadd_pd(a, b, c); }
  static HPRT_FORCE_INLINE D fmsub(D a, D b, D c) { return _mm512_fmsub_pd(a, b, c); }
  static HPRT_FORCE_INLINE D fnmadd(D a, D b, D c) { return _mm512_fnmadd_pd(a, b, c); }
  template <int kCmp>
  static HPRT_FORCE_INLINE __mmask8 cmp(D a, D b) {
    return _mm512_cmp_pd_mask(a, b, kCmp);
  }
  static HPRT_FORCE_INLINE void store(float* p, F f) { _mm256_storeu_ps(p, f); }
#if defined(__AVX512VL__)
  static HPRT_FORCE_INLINE F load(__mmask8 m, const float* p) {
    return _mm256_maskz_loadu_ps(m, p);
  }
#endif
};

#if defined(__AVX512VL__)
template <>
struct Lanes<4> {
  using F = __m128;
  using D = __m256d;
  static HPRT_FORCE_INLINE D wide(F f) { return _mm256_cvtps_pd(f); }
  static HPRT_FORCE_INLINE F narrow(D d) { return _mm256_cvtpd_ps(d); }
  static HPRT_FORCE_INLINE D set(double x) { return _mm256_set1_pd(x); }
  static HPRT_FORCE_INLINE F setf(float x) { return _mm_set1_ps(x); }
  static HPRT_FORCE_INLINE F subf(F a, F b) { return _mm_sub_ps(a, b); }
  static HPRT_FORCE_INLINE D add(D a, D b) { return _mm256_add_pd(a, b); }
  static HPRT_FORCE_INLINE D mul(D a, D b) { return _mm256_mul_pd(a, b); }
  static HPRT_FORCE_INLINE D div(D a, D b) { return _mm256_div_pd(a, b); }
  static HPRT_FORCE_INLINE D fmadd(D a, D b, D c) { return _mm256_fmadd_pd(a, b, c); }
  static HPRT_FORCE_INLINE D fmsub(D a, D b, D c) { return _mm256_fmsub_pd(a, b, c); }
  static HPRT_FORCE_INLINE D fnmadd(D a, D b, D c) { return _mm256_fnmadd_pd(a, b, c); }
  template <int kCmp>
  static HPRT_FORCE_INLINE __mmask8 cmp(D a, D b) {
    return _mm256_cmp_pd_mask(a, b, kCmp);
  }
  static HPRT_FORCE_INLINE void store(float* p, F f) { _mm_storeu_ps(p, f); }
  static HPRT_FORCE_INLINE F load(__mmask8 m, const float* p) { return _mm_maskz_loadu_ps(m, p); }
};
#endif

// The scalar test on W lanes: d[k][a] = vertex k minus the ray origin on
// permuted axis a (kx, ky, kz), in float; shear = (sx, sy, sz). Returns the
// lanes with a hit at tnear < t <= tfar; t, u, v are written for all W lanes
// when any lane hits.
template <int W>
HPRT_FORCE_INLINE __mmask8 watertight_lanes(const typename Lanes<W>::F (&d)[3][3],
                                            const typename Lanes<W>::D (&shear)[3],
                                            typename Lanes<W>::D tnear, typename Lanes<W>::F tfar,
                                            float* t_out, float* u_out, float* v_out) {
  using L = Lanes<W>;
  using D = typename L::D;
  // Sheared 2D vertices: float(x - s*z) in double (s*z exact), back to double.
  D x[3], y[3], z[3];
  for (int k = 0; k < 3; ++k) {
    z[k] = L::wide(d[k][2]);
    x[k] = L::wide(L::narrow(L::fnmadd(shear[0], z[k], L::wide(d[k][0]))));
    y[k] = L::wide(L::narrow(L::fnmadd(shear[1], z[k], L::wide(d[k][1]))));
  }
  // Edge functions: differences of exact products, rounded once.
  const D u = L::fmsub(x[2], y[1], L::mul(y[2], x[1]));
  const D v = L::fmsub(x[0], y[2], L::mul(y[0], x[2]));
  const D w = L::fmsub(x[1], y[0], L::mul(y[1], x[0]));
  const D zero = L::set(0.0);
  const __mmask8 neg = L::template cmp<_CMP_LT_OQ>(u, zero) | L::template cmp<_CMP_LT_OQ>(v, zero) |
                       L::template cmp<_CMP_LT_OQ>(w, zero);
  const __mmask8 pos = L::template cmp<_CMP_GT_OQ>(u, zero) | L::template cmp<_CMP_GT_OQ>(v, zero) |
                       L::template cmp<_CMP_GT_OQ>(w, zero);
  const D det = L::add(L::add(u, v), w);
  __mmask8 ok = __mmask8(~(neg & pos)) & L::template cmp<_CMP_NEQ_UQ>(det, zero);
  if (!ok) return 0;
  const D sz = shear[2];
  const D tt =
      L::fmadd(w, L::mul(sz, z[2]), L::fmadd(v, L::mul(sz, z[1]), L::mul(u, L::mul(sz, z[0]))));
  const D rcp = L::div(L::set(1.0), det);
  const typename L::F t = L::narrow(L::mul(tt, rcp));
  const D td = L::wide(t);
  ok &= L::template cmp<_CMP_LT_OQ>(tnear, td) & L::template cmp<_CMP_LE_OQ>(td, L::wide(tfar));
  if (!ok) return 0;
  L::store(t_out, t);
  L::store(u_out, L::narrow(L::mul(v, rcp)));
  L::store(v_out, L::narrow(L::mul(w, rcp)));
  return ok;
}

}  // namespace detail

class WatertightLanes {
 public:
  // From the 16 lanes' prepared states; usable() is false when they differ
  // in (kx, ky, kz).
  void setup(const WatertightTest::Prepared* prep, const float* tnear) {
    kx_ = prep[0].kx;
    ky_ = prep[0].ky;
    kz_ = prep[0].kz;
    usable_ = true;
    alignas(64) float o[3][16], s[3][16];
    for (int l = 0; l < 16; ++l) {
      const WatertightTest::Prepared& p = prep[l];
      usable_ = usable_ && p.kx == kx_ && p.ky == ky_ && p.kz == kz_;
      o[0][l] = p.org[kx_];
      o[1][l] = p.org[ky_];
      o[2][l] = p.org[kz_];
      s[0][l] = p.sx;
      s[1][l] = p.sy;
      s[2][l] = p.sz;
    }
    for (int h = 0; h < 2; ++h) {
      for (int a = 0; a < 3; ++a) {
        org_[h][a] = _mm256_load_ps(o[a] + 8 * h);
        shear_[h][a] = detail::Lanes<8>::wide(_mm256_load_ps(s[a] + 8 * h));
      }
      tnear_[h] = detail::Lanes<8>::wide(_mm256_loadu_ps(tnear + 8 * h));
    }
  }
  bool usable() const { return usable_; }

  // The lanes of `lanes` whose ray hits triangle i of `tris` with
  // tnear < t <= tfar[lane]; t, u, v are written for every lane of those halves.
  HPRT_FORCE_INLINE __mmask16 intersect(const LeafTriangles& tris, const LeafRange& leaf,
                                        uint32_t i, const float* tfar, __mmask16 lanes, float* t,
                                        float* u, float* v) const {
    const TriangleVerts tv = tris.triangle(leaf, i);
    const float vk[3][3] = {{tv.v0[kx_], tv.v0[ky_], tv.v0[kz_]},
                            {tv.v1[kx_], tv.v1[ky_], tv.v1[kz_]},
                            {tv.v2[kx_], tv.v2[ky_], tv.v2[kz_]}};
    __mmask16 hit = 0;
    for (int h = 0; h < 2; ++h) {
      const __mmask8 want = __mmask8(lanes >> (8 * h));
      if (!want) continue;
      hit |= __mmask16(half(vk, h, tfar + 8 * h, t + 8 * h, u + 8 * h, v + 8 * h) & want)
             << (8 * h);
    }
    return hit;
  }

 private:
  HPRT_FORCE_INLINE __mmask8 half(const float (&vk)[3][3], int h, const float* tfar, float* t_out,
                                  float* u_out, float* v_out) const {
    __m256 d[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) d[k][a] = _mm256_sub_ps(_mm256_set1_ps(vk[k][a]), org_[h][a]);
    return detail::watertight_lanes<8>(d, shear_[h], tnear_[h], _mm256_loadu_ps(tfar), t_out, u_out,
                                       v_out);
  }

  bool usable_ = false;
  int kx_ = 0, ky_ = 1, kz_ = 2;
  __m256 org_[2][3];     // per half: the lanes' org[kx], org[ky], org[kz]
  __m512d shear_[2][3];  // per half: sx, sy, sz
  __m512d tnear_[2];
};

#if defined(__AVX512VL__)
// Triangles [first, first + count) of `leaf` (count 1..W) against one ray:
// the lanes (triangle first + lane) with a hit at tnear < t <= tfar; t, u, v
// are written for all W lanes when any lane hits. Each coordinate of the
// chunk is one masked load from its row of the leaf's verts block.
template <int W>
HPRT_FORCE_INLINE unsigned watertight_leaf(const WatertightTest::Prepared& p,
                                           const LeafTriangles& tris, const LeafRange& leaf,
                                           uint32_t first, uint32_t count, float tnear, float tfar,
                                           float* t, float* u, float* v) {
  using L = detail::Lanes<W>;
  const __mmask8 lanes = __mmask8((1u << count) - 1);
  const float* base =
      tris.vert_row(leaf.block_first, leaf.block_count, 0) + (first - leaf.block_first);
  const size_t rows = leaf.block_count;
  const int axis[3] = {p.kx, p.ky, p.kz};
  typename L::F d[3][3];
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a)
      d[k][a] = L::subf(L::load(lanes, base + (3 * k + axis[a]) * rows), L::setf(p.org[axis[a]]));
  const typename L::D shear[3] = {L::set(double(p.sx)), L::set(double(p.sy)), L::set(double(p.sz))};
  return detail::watertight_lanes<W>(d, shear, L::set(double(tnear)), L::setf(tfar), t, u, v) &
         lanes;
}
#endif

}  // namespace hprt

#endif  // __AVX512F__
