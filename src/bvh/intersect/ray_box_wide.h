// The robust slab test of ray_box.h against the N child boxes of a wide
// node at once: one SIMD lane per child (SSE for 4, AVX for 8), the same
// operations lane by lane as slab_robust() (sub, mul by the reciprocal, the
// far planes by the Ize-padded one, NaN slab values dropped), so a child is
// hit exactly when slab_robust() says so, with the same entry distance.
#pragma once

#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "bvh/intersect/ray_box.h"
#include "bvh/layout/node_wide.h"
#include "core/force_inline.h"

namespace hprt {

// Per-ray data: SlabRay's, with the octant as rows of WideNode::bounds.
struct WideSlabRay {
  SlabRay s;
  int near_row[3] = {0, 2, 4};
  int far_row[3] = {1, 3, 5};

  // The rows come from the direction's sign bits, not from s.near_off: that
  // would load what was just stored as separate ints, a store-forwarding
  // stall on every ray.
  HPRT_FORCE_INLINE explicit WideSlabRay(const Ray& r) : s(r) {
    for (int a = 0; a < 3; ++a) {
      const int neg = std::signbit(r.dir[a]) ? 1 : 0;  // near plane is the box maximum
      near_row[a] = 2 * a + neg;
      far_row[a] = 2 * a + 1 - neg;
    }
  }
};

// Bit i of the result: child i's box overlaps the ray on [tmin, tmax];
// entry[i] = max(tmin, its entry distance) for every lane (meaningful for
// hit lanes only).
template <int N>
HPRT_FORCE_INLINE unsigned slab_wide(const WideSlabRay& r, const WideNode<N>& node, float tmin,
                                     float tmax, float* entry) {
  unsigned mask = 0;
  for (int i = 0; i < N; ++i) {
    const float tnx = (node.bounds[r.near_row[0]][i] - r.s.org.x) * r.s.rcp_near.x;
    const float tny = (node.bounds[r.near_row[1]][i] - r.s.org.y) * r.s.rcp_near.y;
    const float tnz = (node.bounds[r.near_row[2]][i] - r.s.org.z) * r.s.rcp_near.z;
    const float tfx = (node.bounds[r.far_row[0]][i] - r.s.org.x) * r.s.rcp_far.x;
    const float tfy = (node.bounds[r.far_row[1]][i] - r.s.org.y) * r.s.rcp_far.y;
    const float tfz = (node.bounds[r.far_row[2]][i] - r.s.org.z) * r.s.rcp_far.z;
    const float t0 = robust_max(tnx, robust_max(tny, robust_max(tnz, tmin)));
    const float t1 = robust_min(tfx, robust_min(tfy, robust_min(tfz, tmax)));
    entry[i] = t0;
    mask |= unsigned(t0 <= t1) << i;
  }
  return mask;
}

// _mm_max_ps(a, b) / _mm_min_ps(a, b) return b when a is NaN, i.e.
// robust_max / robust_min with the slab value first.
#if defined(__SSE2__)
template <>
HPRT_FORCE_INLINE unsigned slab_wide<4>(const WideSlabRay& r, const WideNode<4>& node, float tmin,
                                        float tmax, float* entry) {
  const auto plane = [&](int row, float o, float rcp) {
    return _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[row]), _mm_set1_ps(o)), _mm_set1_ps(rcp));
  };
  const __m128 tn = _mm_max_ps(
      plane(r.near_row[0], r.s.org.x, r.s.rcp_near.x),
      _mm_max_ps(plane(r.near_row[1], r.s.org.y, r.s.rcp_near.y),
                 _mm_max_ps(plane(r.near_row[2], r.s.org.z, r.s.rcp_near.z), _mm_set1_ps(tmin))));
  const __m128 tf = _mm_min_ps(
      plane(r.far_row[0], r.s.org.x, r.s.rcp_far.x),
      _mm_min_ps(plane(r.far_row[1], r.s.org.y, r.s.rcp_far.y),
                 _mm_min_ps(plane(r.far_row[2], r.s.org.z, r.s.rcp_far.z), _mm_set1_ps(tmax))));
  _mm_storeu_ps(entry, tn);
  return unsigned(_mm_movemask_ps(_mm_cmple_ps(tn, tf)));
}
#endif

#if defined(__AVX__)
template <>
HPRT_FORCE_INLINE unsigned slab_wide<8>(const WideSlabRay& r, const WideNode<8>& node, float tmin,
                                        float tmax, float* entry) {
  const auto plane = [&](int row, float o, float rcp) {
    return _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[row]), _mm256_set1_ps(o)),
                         _mm256_set1_ps(rcp));
  };
  const __m256 tn = _mm256_max_ps(
      plane(r.near_row[0], r.s.org.x, r.s.rcp_near.x),
      _mm256_max_ps(
          plane(r.near_row[1], r.s.org.y, r.s.rcp_near.y),
          _mm256_max_ps(plane(r.near_row[2], r.s.org.z, r.s.rcp_near.z), _mm256_set1_ps(tmin))));
  const __m256 tf = _mm256_min_ps(
      plane(r.far_row[0], r.s.org.x, r.s.rcp_far.x),
      _mm256_min_ps(
          plane(r.far_row[1], r.s.org.y, r.s.rcp_far.y),
          _mm256_min_ps(plane(r.far_row[2], r.s.org.z, r.s.rcp_far.z), _mm256_set1_ps(tmax))));
  _mm256_storeu_ps(entry, tn);
  return unsigned(_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ)));
}
#endif

}  // namespace hprt
