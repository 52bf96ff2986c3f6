// WatertightTest::intersect for the 16 rays of a packet at once (AVX-512, the
// doubles in two halves of 8), for packets whose rays share the axis
// permutation (kx, ky, kz): camera rays and their shadow and mirror rays
// nearly always do. Lane by lane the operations are the scalar test's, in the
// same order and precision (the float differences, the shear and edge
// functions in double with exact products, the fused t sum, one division),
// so a lane hits exactly when the scalar test says so, with the same t, u, v.
#pragma once

#if defined(__AVX512F__)
#include <immintrin.h>

#include <cstdint>

#include "bvh/leaf_triangles.h"
#include "bvh/triangle_test.h"
#include "core/force_inline.h"

namespace hprt {

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
        shear_[h][a] = wide(_mm256_load_ps(s[a] + 8 * h));
      }
      tnear_[h] = wide(_mm256_loadu_ps(tnear + 8 * h));
    }
  }
  bool usable() const { return usable_; }

  // The lanes of `lanes` whose ray hits triangle i of `tris` with
  // tnear < t <= tfar[lane]; t, u, v are written for every lane of those halves.
  HPRT_FORCE_INLINE __mmask16 intersect(const LeafTriangles& tris, uint32_t i, const float* tfar,
                                        __mmask16 lanes, float* t, float* u, float* v) const {
    const TriangleVerts& tv = tris.verts[i];
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
  // Float <-> double conversions through their mask variants: the plain ones
  // pass an undefined operand that g++ 12 reports as maybe-uninitialized.
  static HPRT_FORCE_INLINE __m512d wide(__m256 f) {
    return _mm512_mask_cvtps_pd(_mm512_setzero_pd(), 0xFF, f);
  }
  static HPRT_FORCE_INLINE __m256 narrow(__m512d d) {
    return _mm512_mask_cvtpd_ps(_mm256_setzero_ps(), 0xFF, d);
  }

  HPRT_FORCE_INLINE __mmask8 half(const float (&vk)[3][3], int h, const float* tfar, float* t_out,
                                  float* u_out, float* v_out) const {
    // Vertex minus origin in float, per permuted axis (the scalar `v - org`).
    __m256 d[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) d[k][a] = _mm256_sub_ps(_mm256_set1_ps(vk[k][a]), org_[h][a]);
    // Sheared 2D vertices: float(x - s*z) in double (s*z exact), back to double.
    __m512d x[3], y[3], z[3];
    for (int k = 0; k < 3; ++k) {
      z[k] = wide(d[k][2]);
      x[k] = wide(narrow(_mm512_fnmadd_pd(shear_[h][0], z[k], wide(d[k][0]))));
      y[k] = wide(narrow(_mm512_fnmadd_pd(shear_[h][1], z[k], wide(d[k][1]))));
    }
    // Edge functions: differences of exact products, rounded once.
    const __m512d u = _mm512_fmsub_pd(x[2], y[1], _mm512_mul_pd(y[2], x[1]));
    const __m512d v = _mm512_fmsub_pd(x[0], y[2], _mm512_mul_pd(y[0], x[2]));
    const __m512d w = _mm512_fmsub_pd(x[1], y[0], _mm512_mul_pd(y[1], x[0]));
    const __m512d zero = _mm512_setzero_pd();
    const __mmask8 neg = _mm512_cmp_pd_mask(u, zero, _CMP_LT_OQ) |
                         _mm512_cmp_pd_mask(v, zero, _CMP_LT_OQ) |
                         _mm512_cmp_pd_mask(w, zero, _CMP_LT_OQ);
    const __mmask8 pos = _mm512_cmp_pd_mask(u, zero, _CMP_GT_OQ) |
                         _mm512_cmp_pd_mask(v, zero, _CMP_GT_OQ) |
                         _mm512_cmp_pd_mask(w, zero, _CMP_GT_OQ);
    const __m512d det = _mm512_add_pd(_mm512_add_pd(u, v), w);
    __mmask8 ok = __mmask8(~(neg & pos)) & _mm512_cmp_pd_mask(det, zero, _CMP_NEQ_UQ);
    if (!ok) return 0;
    const __m512d sz = shear_[h][2];
    const __m512d tt = _mm512_fmadd_pd(
        w, _mm512_mul_pd(sz, z[2]),
        _mm512_fmadd_pd(v, _mm512_mul_pd(sz, z[1]), _mm512_mul_pd(u, _mm512_mul_pd(sz, z[0]))));
    const __m512d rcp = _mm512_div_pd(_mm512_set1_pd(1.0), det);
    const __m256 t = narrow(_mm512_mul_pd(tt, rcp));
    const __m512d td = wide(t);
    ok &= _mm512_cmp_pd_mask(tnear_[h], td, _CMP_LT_OQ) &
          _mm512_cmp_pd_mask(td, wide(_mm256_loadu_ps(tfar)), _CMP_LE_OQ);
    if (!ok) return 0;
    _mm256_storeu_ps(t_out, t);
    _mm256_storeu_ps(u_out, narrow(_mm512_mul_pd(v, rcp)));
    _mm256_storeu_ps(v_out, narrow(_mm512_mul_pd(w, rcp)));
    return ok;
  }

  bool usable_ = false;
  int kx_ = 0, ky_ = 1, kz_ = 2;
  __m256 org_[2][3];     // per half: the lanes' org[kx], org[ky], org[kz]
  __m512d shear_[2][3];  // per half: sx, sy, sz
  __m512d tnear_[2];
};

}  // namespace hprt

#endif  // __AVX512F__
