// make_prim_info's fill, 16 triangles per step (AVX-512): indices and
// vertices gathered, validity decided as TriangleMesh::triangle_valid does,
// boxes, centres and refs computed lane by lane with the scalar code's
// operations in its order (a box is min(min(a, b), c) as three extends of an
// empty box give, the centre (min + max) * 0.5), so every value written is
// the scalar fill's, bit for bit. A step whose 16 triangles are not all valid
// writes nothing and is left to the scalar loop, which keeps the order of
// the valid ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "bvh/input/prim_info.h"
#include "core/min_max16.h"
#include "core/triangle_mesh.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#define HPRT_HAS_PRIM_INFO_LANES 1

namespace hprt {

using detail::max16;  // hprt::min/max's rule; mask forms of the intrinsics, as
using detail::min16;  // the other masked forms below (g++ 12 warnings)

// Scene and centroid bounds of the triangles filled 16 at a time, per lane.
struct PrimInfoLanesBounds {
  __m512 lo[3], hi[3];    // boxes
  __m512 clo[3], chi[3];  // centres
  PrimInfoLanesBounds() {
    for (int a = 0; a < 3; ++a) {
      lo[a] = clo[a] = _mm512_set1_ps(std::numeric_limits<float>::infinity());
      hi[a] = chi[a] = _mm512_set1_ps(-std::numeric_limits<float>::infinity());
    }
  }
  // Reduced into `boxes` and `centres` (min/max: exact in any order; only
  // the sign of a zero bound may differ from a sequential reduction).
  void reduce_into(AABB& boxes, AABB& centres) const {
    alignas(64) float l[3][16], h[3][16], cl[3][16], ch[3][16];
    for (int a = 0; a < 3; ++a) {
      _mm512_store_ps(l[a], lo[a]);
      _mm512_store_ps(h[a], hi[a]);
      _mm512_store_ps(cl[a], clo[a]);
      _mm512_store_ps(ch[a], chi[a]);
    }
    for (int k = 0; k < 16; ++k) {
      boxes.extend(AABB({l[0][k], l[1][k], l[2][k]}, {h[0][k], h[1][k], h[2][k]}));
      centres.extend(AABB({cl[0][k], cl[1][k], cl[2][k]}, {ch[0][k], ch[1][k], ch[2][k]}));
    }
  }
};

// Whether the mesh's vertex offsets (3 floats a vertex) fit the gathers'
// 32-bit signed indices.
inline bool prim_info_lanes_fit(const TriangleMesh& m) {
  return m.positions.size() < (size_t{1} << 29);
}

// Triangles [i, i + 16) of mesh `geom`, when all are valid: boxes, centres
// (when `centroids` is not null) and refs written at slot w on, bounds
// extended; returns false, writing nothing, when any is not.
inline bool fill_prim_info_16(const TriangleMesh& m, uint32_t geom, size_t i, AABB* bounds,
                              Vec3f* centroids, PrimRef* refs, PrimInfoLanesBounds& acc) {
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m512i three = _mm512_set1_epi32(3);
  const __m512i lane3 = _mm512_mullo_epi32(lane, three);
  const int* tri = reinterpret_cast<const int*>(m.triangles.data() + i);
  const __m512i nverts = _mm512_set1_epi32(static_cast<int>(m.positions.size()));
  __m512i offset[3];
  __mmask16 ok = 0xffff;
  for (int k = 0; k < 3; ++k) {
    const __m512i idx = _mm512_mask_i32gather_epi32(
        _mm512_setzero_si512(), 0xffff, _mm512_add_epi32(lane3, _mm512_set1_epi32(k)), tri, 4);
    ok &= _mm512_cmplt_epu32_mask(idx, nverts);
    offset[k] = _mm512_mullo_epi32(idx, three);
  }
  if (ok != 0xffff) return false;
  const float* pos = &m.positions.data()->x;
  __m512 p[3][3];  // vertex k, axis a
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) {
      p[k][a] = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xffff,
                                         _mm512_add_epi32(offset[k], _mm512_set1_epi32(a)), pos, 4);
      ok &= ~_mm512_fpclass_ps_mask(p[k][a], 0x99);  // NaN or infinity
    }
  if (ok != 0xffff) return false;
  // Nonzero area as nonzero_area() decides it: a normal component is zero
  // exactly when its two products (exact in double) are equal.
  __m512 e1[3], e2[3];
  for (int a = 0; a < 3; ++a) {
    e1[a] = _mm512_sub_ps(p[1][a], p[0][a]);
    e2[a] = _mm512_sub_ps(p[2][a], p[0][a]);
  }
  __mmask16 nonzero = 0;
  for (int h = 0; h < 2; ++h) {
    const auto half = [h](__m512 v) {
      return _mm512_maskz_cvtps_pd(0xff, h ? _mm512_maskz_extractf32x8_ps(0xff, v, 1)
                                           : _mm512_maskz_extractf32x8_ps(0xff, v, 0));
    };
    __m512d d1[3], d2[3];
    for (int a = 0; a < 3; ++a) d1[a] = half(e1[a]), d2[a] = half(e2[a]);
    __mmask8 nz = 0;
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      nz |=
          _mm512_cmp_pd_mask(_mm512_mul_pd(d1[b], d2[c]), _mm512_mul_pd(d1[c], d2[b]), _CMP_NEQ_OQ);
    }
    nonzero |= __mmask16(nz) << (8 * h);
  }
  if (nonzero != 0xffff) return false;

  const __m512i lane6 = _mm512_add_epi32(lane3, lane3);
  float* box = &bounds->min.x;
  const __m512 half = _mm512_set1_ps(0.5f);
  for (int a = 0; a < 3; ++a) {
    const __m512 lo = min16(min16(p[0][a], p[1][a]), p[2][a]);
    const __m512 hi = max16(max16(p[0][a], p[1][a]), p[2][a]);
    const __m512 centre = _mm512_mul_ps(_mm512_add_ps(lo, hi), half);
    _mm512_i32scatter_ps(box, _mm512_add_epi32(lane6, _mm512_set1_epi32(a)), lo, 4);
    _mm512_i32scatter_ps(box, _mm512_add_epi32(lane6, _mm512_set1_epi32(3 + a)), hi, 4);
    if (centroids)
      _mm512_i32scatter_ps(&centroids->x, _mm512_add_epi32(lane3, _mm512_set1_epi32(a)), centre, 4);
    acc.lo[a] = min16(acc.lo[a], lo);
    acc.hi[a] = max16(acc.hi[a], hi);
    acc.clo[a] = min16(acc.clo[a], centre);
    acc.chi[a] = max16(acc.chi[a], centre);
  }
  // PrimRef {geom_id, prim_id}: geom in the low half of each 64-bit pair.
  static_assert(sizeof(PrimRef) == 8);
  const __m512i prim = _mm512_add_epi32(_mm512_set1_epi32(static_cast<int>(i)), lane);
  const __m512i g = _mm512_set1_epi64(geom);
  for (int h = 0; h < 2; ++h) {
    const __m256i p8 = h ? _mm512_maskz_extracti64x4_epi64(0xf, prim, 1)
                         : _mm512_maskz_extracti64x4_epi64(0xf, prim, 0);
    const __m512i ref = _mm512_or_si512(
        _mm512_maskz_slli_epi64(0xff, _mm512_maskz_cvtepu32_epi64(0xff, p8), 32), g);
    _mm512_storeu_si512(refs + 8 * h, ref);
  }
  return true;
}

}  // namespace hprt
#endif
