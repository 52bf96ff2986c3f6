// WatertightTest::intersect on double lanes (AVX-512), two ways: lanes over
// the 16 rays of a packet against one triangle (WatertightLanes, the doubles
// in two halves of 8), for packets whose rays share the axis permutation
// (kx, ky, kz): camera rays and their shadow and mirror rays nearly always
// do; and lanes over up to 8 (or 4) triangles of a leaf against one ray
// (watertight_leaf<8>, watertight_leaf<4>), loaded a row of the leaf's verts
// block at a time. Lane by lane the operations are the scalar test's, in the
// same order and precision (the differences, shear and edge functions in
// double, the fused t sum, one division). Their error bound is the ray's
// lane_bound, one number (ray_triangle_exact.h); lanes it cannot decide go
// to the scalar test, which uses its own tighter bound and decides the rest
// exactly. Either way a lane hits exactly when the scalar test says so, with
// the same t, u, v.
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
  static HPRT_FORCE_INLINE D add(D a, D b) { return _mm512_add_pd(a, b); }
  static HPRT_FORCE_INLINE D sub(D a, D b) { return _mm512_sub_pd(a, b); }
  static HPRT_FORCE_INLINE D abs(D a) { return _mm512_abs_pd(a); }
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
  static HPRT_FORCE_INLINE D add(D a, D b) { return _mm256_add_pd(a, b); }
  static HPRT_FORCE_INLINE D sub(D a, D b) { return _mm256_sub_pd(a, b); }
  static HPRT_FORCE_INLINE D abs(D a) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a); }
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

// The scalar test's double path on W lanes: vert[k][a] = vertex k on
// permuted axis a (kx, ky, kz), org the ray origin on those axes, shear =
// (sx, sy, sz), bound = the rays' lane_bound. Returns the lanes the double
// path decides are hit at tnear < t <= tfar (t, u, v are then written for all
// W lanes); `unsure` gets the lanes whose edge-function signs the bound
// cannot decide, which the caller hands to the scalar test.
template <int W>
HPRT_FORCE_INLINE __mmask8 watertight_lanes(const typename Lanes<W>::D (&vert)[3][3],
                                            const typename Lanes<W>::D (&org)[3],
                                            const typename Lanes<W>::D (&shear)[3],
                                            typename Lanes<W>::D bound, typename Lanes<W>::D tnear,
                                            typename Lanes<W>::F tfar, float* t_out, float* u_out,
                                            float* v_out, __mmask8& unsure) {
  using L = Lanes<W>;
  using D = typename L::D;
  D x[3], y[3], z[3];
  for (int k = 0; k < 3; ++k) {
    const D dx = L::sub(vert[k][0], org[0]), dy = L::sub(vert[k][1], org[1]);
    z[k] = L::sub(vert[k][2], org[2]);
    x[k] = L::fnmadd(shear[0], z[k], dx);
    y[k] = L::fnmadd(shear[1], z[k], dy);
  }
  // Edge functions: a product, then an fma.
  const D u = L::fmsub(x[2], y[1], L::mul(y[2], x[1]));
  const D v = L::fmsub(x[0], y[2], L::mul(y[0], x[2]));
  const D w = L::fmsub(x[1], y[0], L::mul(y[1], x[0]));
  const __mmask8 sure = L::template cmp<_CMP_GT_OQ>(L::abs(u), bound) &
                        L::template cmp<_CMP_GT_OQ>(L::abs(v), bound) &
                        L::template cmp<_CMP_GT_OQ>(L::abs(w), bound);
  unsure = __mmask8(~sure);
  const D zero = L::set(0.0);
  const __mmask8 nu = L::template cmp<_CMP_LT_OQ>(u, zero),
                 nv = L::template cmp<_CMP_LT_OQ>(v, zero),
                 nw = L::template cmp<_CMP_LT_OQ>(w, zero);
  __mmask8 ok = sure & __mmask8(~((nu ^ nv) | (nu ^ nw)));
  if (!ok) return 0;
  const D det = L::add(L::add(u, v), w);
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
  // From the 16 lanes' prepared states and tnear (both must outlive this
  // object's use); usable() is false when they differ in (kx, ky, kz).
  void setup(const WatertightTest::Prepared* prep, const float* tnear) {
    prep_ = prep;
    tnear_lane_ = tnear;
    kx_ = prep[0].kx;
    ky_ = prep[0].ky;
    kz_ = prep[0].kz;
    usable_ = true;
    alignas(64) double o[3][16], s[3][16], b[16];
    for (int l = 0; l < 16; ++l) {
      const WatertightTest::Prepared& p = prep[l];
      usable_ = usable_ && p.kx == kx_ && p.ky == ky_ && p.kz == kz_;
      o[0][l] = p.ox;
      o[1][l] = p.oy;
      o[2][l] = p.oz;
      s[0][l] = p.sx;
      s[1][l] = p.sy;
      s[2][l] = p.sz;
      b[l] = p.lane_bound;
    }
    for (int h = 0; h < 2; ++h) {
      for (int a = 0; a < 3; ++a) {
        org_[h][a] = _mm512_load_pd(o[a] + 8 * h);
        shear_[h][a] = _mm512_load_pd(s[a] + 8 * h);
      }
      tnear_[h] = detail::Lanes<8>::wide(_mm256_loadu_ps(tnear + 8 * h));
      bound_[h] = _mm512_load_pd(b + 8 * h);
    }
  }
  bool usable() const { return usable_; }

  // The lanes of `lanes` whose ray hits triangle i of `tris` with
  // tnear < t <= tfar[lane]; t, u, v are written for every lane of those halves.
  HPRT_FORCE_INLINE __mmask16 intersect(const LeafTriangles& tris, const LeafRange& leaf,
                                        uint32_t i, const float* tfar, __mmask16 lanes, float* t,
                                        float* u, float* v) const {
    const TriangleVerts tv = tris.triangle(leaf, i);
    // The vertices on the permuted axes, broadcast once for both halves.
    const Vec3f* vk[3] = {&tv.v0, &tv.v1, &tv.v2};
    const int axis[3] = {kx_, ky_, kz_};
    __m512d vert[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) vert[k][a] = _mm512_set1_pd(double((*vk[k])[axis[a]]));
    __mmask16 hit = 0;
    for (int h = 0; h < 2; ++h) {
      const __mmask8 want = __mmask8(lanes >> (8 * h));
      if (!want) continue;
      __mmask8 unsure = 0;
      __mmask8 half_hit = detail::watertight_lanes<8>(vert, org_[h], shear_[h], bound_[h],
                                                      tnear_[h], _mm256_loadu_ps(tfar + 8 * h),
                                                      t + 8 * h, u + 8 * h, v + 8 * h, unsure) &
                          want;
      // Lanes the bound cannot decide: the scalar test, which decides them
      // exactly (rare: rays through or within ~1e-13 of an edge).
      for (unsigned m = unsure & want; m; m &= m - 1) {
        const int l = 8 * h + __builtin_ctz(m);
        TriangleHit th;
        if (WatertightTest::intersect(prep_[l], tv.v0, tv.v1, tv.v2, tnear_lane_[l], tfar[l], th)) {
          half_hit |= __mmask8(1u << (l - 8 * h));
          t[l] = th.t;
          u[l] = th.u;
          v[l] = th.v;
        }
      }
      hit |= __mmask16(half_hit) << (8 * h);
    }
    return hit;
  }

 private:
  const WatertightTest::Prepared* prep_ = nullptr;
  const float* tnear_lane_ = nullptr;
  bool usable_ = false;
  int kx_ = 0, ky_ = 1, kz_ = 2;
  __m512d org_[2][3];    // per half: the lanes' org[kx], org[ky], org[kz]
  __m512d shear_[2][3];  // per half: sx, sy, sz
  __m512d tnear_[2];
  __m512d bound_[2];  // per half: the lanes' lane_bound
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
  typename L::D vert[3][3];
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a)
      vert[k][a] = L::wide(L::load(lanes, base + (3 * k + axis[a]) * rows));
  const typename L::D org[3] = {L::set(p.ox), L::set(p.oy), L::set(p.oz)};
  const typename L::D shear[3] = {L::set(p.sx), L::set(p.sy), L::set(p.sz)};
  __mmask8 unsure = 0;
  unsigned hit =
      detail::watertight_lanes<W>(vert, org, shear, L::set(p.lane_bound), L::set(double(tnear)),
                                  L::setf(tfar), t, u, v, unsure) &
      lanes;
  // Lanes the bound cannot decide: the scalar test decides them exactly.
  for (unsigned m = unsure & lanes; m; m &= m - 1) {
    const int l = __builtin_ctz(m);
    TriangleHit th;
    if (WatertightTest::intersect(p, tris, leaf, first + uint32_t(l), tnear, tfar, th)) {
      hit |= 1u << l;
      t[l] = th.t;
      u[l] = th.u;
      v[l] = th.v;
    }
  }
  return hit;
}
#endif

}  // namespace hprt

#endif  // __AVX512F__
