// Whether a group of rays is worth tracing as one packet: all valid, origins
// within `max_origin_offset` of the first one's (per component), directions
// within ~25 degrees (cos >= 0.9) of the first one's: camera rays, and the
// shadow and mirror rays of neighbouring pixels, not random or scattered
// ones. Both backends use it, so they pick the same groups.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/ray.h"
#include "core/ray_fields16.h"

namespace hprt {

// max_origin_offset as a fraction of the scene's largest extent: wide enough
// that the shadow and reflection rays of neighbouring pixels qualify (with
// 1/1000 almost none would), and packets of them still trace faster than
// single rays in both backends.
inline constexpr float kCoherentOriginFraction = 0.05f;

#if defined(__AVX512F__)
// rays_coherent for a group of 16 (both backends' packet size): the same
// tests with one ray per lane, instead of 16 scalar square roots and 48
// divisions per group, which camera-ray batches would spend much time on.
inline bool rays_coherent16(const Ray* r, float max_origin_offset) {
  __m512 c[8];
  load_ray_fields16(r, c);
  const __m512 org[3] = {c[0], c[1], c[2]}, dir[3] = {c[4], c[5], c[6]};
  const __m512 tnear = c[3], tfar = c[7];
  // ray_valid: |component| <= the limit (NaN fails), a nonzero direction,
  // 0 <= tnear <= tfar.
  const __m512 limit = _mm512_set1_ps(kRayComponentLimit), zero = _mm512_setzero_ps();
  __mmask16 ok = _mm512_cmp_ps_mask(tnear, zero, _CMP_GE_OQ);
  ok = _mm512_mask_cmp_ps_mask(ok, tnear, tfar, _CMP_LE_OQ);
  __mmask16 moves = 0;
  for (int a = 0; a < 3; ++a) {
    ok = _mm512_mask_cmp_ps_mask(ok, _mm512_abs_ps(org[a]), limit, _CMP_LE_OQ);
    ok = _mm512_mask_cmp_ps_mask(ok, _mm512_abs_ps(dir[a]), limit, _CMP_LE_OQ);
    moves |= _mm512_cmp_ps_mask(dir[a], zero, _CMP_NEQ_UQ);
  }
  ok &= moves;
  // Origins within max_origin_offset of the first ray's, per component.
  const __m512i first = _mm512_setzero_si512();
  const __m512 offset = _mm512_set1_ps(max_origin_offset);
  for (int a = 0; a < 3; ++a) {
    const __m512 o = _mm512_sub_ps(org[a], _mm512_maskz_permutexvar_ps(0xFFFF, first, org[a]));
    ok = _mm512_mask_cmp_ps_mask(ok, _mm512_abs_ps(o), offset, _CMP_LE_OQ);
  }
  // Unit directions within cos >= 0.9 of the first ray's (NaN: not coherent).
  // (Masked forms: g++ 12 reports the plain ones' undefined pass-through
  // operand as maybe-uninitialized.)
  const __m512 len = _mm512_maskz_sqrt_ps(
      0xFFFF, _mm512_fmadd_ps(dir[2], dir[2],
                              _mm512_fmadd_ps(dir[1], dir[1], _mm512_mul_ps(dir[0], dir[0]))));
  __m512 cosine = zero;
  for (int a = 0; a < 3; ++a) {
    const __m512 unit = _mm512_div_ps(dir[a], len);
    cosine = _mm512_fmadd_ps(unit, _mm512_maskz_permutexvar_ps(0xFFFF, first, unit), cosine);
  }
  ok = _mm512_mask_cmp_ps_mask(ok, cosine, _mm512_set1_ps(0.9f), _CMP_GE_OQ);
  return ok == 0xFFFF;
}
#endif

// The tests ray by ray, any n.
inline bool rays_coherent_each(const Ray* r, size_t n, float max_origin_offset) {
  if (n == 0 || !ray_valid(r[0])) return false;
  const Vec3f d0 = normalize(r[0].dir);  // tiny or huge dirs give NaN below
  for (size_t i = 1; i < n; ++i) {
    if (!ray_valid(r[i])) return false;
    const Vec3f o = r[i].org - r[0].org;
    if (std::max({std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)}) > max_origin_offset)
      return false;
    if (!(dot(normalize(r[i].dir), d0) >= 0.9f)) return false;  // NaN: not coherent
  }
  return true;
}

inline bool rays_coherent(const Ray* r, size_t n, float max_origin_offset) {
#if defined(__AVX512F__)
  if (n == 16) return rays_coherent16(r, max_origin_offset);
#endif
  return rays_coherent_each(r, n, max_origin_offset);
}

}  // namespace hprt
