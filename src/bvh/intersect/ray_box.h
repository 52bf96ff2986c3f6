// Robust ray/box slab test (Kay & Kajiya slabs with reciprocal directions).
// - Axis-parallel rays: a ±0 direction component gives a ±inf reciprocal; an
//   origin exactly on a slab plane then gives 0 * inf = NaN. Every min/max is
//   written `a < b ? a : b` with the slab value first, so a NaN slab value is
//   dropped (that slab does not constrain the ray: the origin on a plane
//   counts as inside), as in madmann91/bvh's robust_min/robust_max and
//   Williams et al., "An Efficient and Robust Ray-Box Intersection Algorithm"
//   (JGT 2005). NaN never creates a hit: the comparison entry <= exit is false.
// - Conservative: the far distances use the reciprocal scaled by 1 + 2·gamma(3)
//   (Ize, "Robust BVH Ray Traversal", JCGT 2013; gamma(n) = n·eps / (1 - n·eps),
//   eps = 2^-24 as in pbrt-v4), so rounding in (plane - org) * rcp never loses
//   a box the exact ray touches; the near distances use it scaled by
//   1 - 2·gamma(3), so the entry distance is never above the exact one and a
//   box is not skipped when a hit on its face equals the closest t so far
//   (ties then go by leaf index whatever the visiting order, leaf_intersect.h).
#pragma once

#include <cmath>
#include <cstdint>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "core/aabb.h"
#include "core/force_inline.h"
#include "core/ray.h"
#include "core/vec.h"

namespace hprt {

// pbrt-v4's gamma(n): bound on the relative error of n float operations.
constexpr float float_gamma(int n) {
  constexpr float kEps = 0.5f * 1.1920928955078125e-07f;  // 2^-24, unit roundoff
  return (float(n) * kEps) / (1.0f - float(n) * kEps);
}

inline constexpr float kSlabNearPad = 1.0f - 2.0f * float_gamma(3);
inline constexpr float kSlabFarPad = 1.0f + 2.0f * float_gamma(3);

// Slab values drop a NaN in `a` (the slab distance) and keep `b`.
inline float robust_min(float a, float b) { return a < b ? a : b; }
inline float robust_max(float a, float b) { return a > b ? a : b; }

// Boxes are read as 8 floats: lo.x lo.y lo.z (pad) hi.x hi.y hi.z (pad), which
// is BinaryNode's layout; box_floats() makes that from an AABB.
inline constexpr int kSlabHiOffset = 4;

struct BoxFloats {
  float f[8];
};
inline BoxFloats box_floats(const AABB& b) {
  return {{b.min.x, b.min.y, b.min.z, 0.0f, b.max.x, b.max.y, b.max.z, 0.0f}};
}

// Per-ray data for the slab test, computed once before traversal.
struct SlabRay {
  Vec3f org;
  Vec3f rcp_near;  // (1 / dir) * (1 - 2·gamma(3)) for the near planes (±inf for ±0)
  Vec3f rcp_far;   // (1 / dir) * (1 + 2·gamma(3)) for the far planes (Ize 2013)
  // Octant: float offsets of the near and far plane per axis. The near plane
  // is the box maximum when the direction's sign bit is set (-0 included).
  int near_off[3] = {0, 1, 2};
  int far_off[3] = {4, 5, 6};

  SlabRay() = default;
  HPRT_FORCE_INLINE explicit SlabRay(const Ray& r) : org(r.org) {
    for (int a = 0; a < 3; ++a) {
      const float rcp = 1.0f / r.dir[a];
      rcp_near[a] = rcp * kSlabNearPad;
      rcp_far[a] = rcp * kSlabFarPad;
      const bool neg = std::signbit(r.dir[a]);
      near_off[a] = a + (neg ? kSlabHiOffset : 0);
      far_off[a] = a + (neg ? 0 : kSlabHiOffset);
    }
  }
};

// Whether the box overlaps the ray on [tmin, tmax]; `entry` gets
// max(tmin, box entry distance) for near-first ordering and early exit.
HPRT_FORCE_INLINE bool slab_robust(const SlabRay& r, const float* box, float tmin, float tmax,
                                   float& entry) {
  const float tnx = (box[r.near_off[0]] - r.org.x) * r.rcp_near.x;
  const float tny = (box[r.near_off[1]] - r.org.y) * r.rcp_near.y;
  const float tnz = (box[r.near_off[2]] - r.org.z) * r.rcp_near.z;
  const float tfx = (box[r.far_off[0]] - r.org.x) * r.rcp_far.x;
  const float tfy = (box[r.far_off[1]] - r.org.y) * r.rcp_far.y;
  const float tfz = (box[r.far_off[2]] - r.org.z) * r.rcp_far.z;
  const float t0 = robust_max(tnx, robust_max(tny, robust_max(tnz, tmin)));
  const float t1 = robust_min(tfx, robust_min(tfy, robust_min(tfz, tmax)));
  entry = t0;
  return t0 <= t1;
}

#if defined(__AVX2__)
// The same test for the two adjacent children of a binary node at once
// (AVX2, 8 lanes = two 32-byte nodes). Each node's floats are permuted so
// lanes 0-3 hold its near planes (x, y, z, x again) and lanes 4-7 its far
// planes; the two nodes' halves are then regrouped (near of both, far of
// both). _mm256_max_ps(a, b) is `a > b ? a : b` per lane, i.e. robust_max with
// the slab value first, so NaN slab distances drop out exactly as in
// slab_robust(), and the result equals two slab_robust() calls.
struct SlabRayPair {
  __m256 org, rcp_near, rcp_far;
  __m256i perm;

  HPRT_FORCE_INLINE explicit SlabRayPair(const SlabRay& r) {
    org = _mm256_setr_ps(r.org.x, r.org.y, r.org.z, r.org.x, r.org.x, r.org.y, r.org.z, r.org.x);
    rcp_near = _mm256_setr_ps(r.rcp_near.x, r.rcp_near.y, r.rcp_near.z, r.rcp_near.x, r.rcp_near.x,
                              r.rcp_near.y, r.rcp_near.z, r.rcp_near.x);
    rcp_far = _mm256_setr_ps(r.rcp_far.x, r.rcp_far.y, r.rcp_far.z, r.rcp_far.x, r.rcp_far.x,
                             r.rcp_far.y, r.rcp_far.z, r.rcp_far.x);
    perm = _mm256_setr_epi32(r.near_off[0], r.near_off[1], r.near_off[2], r.near_off[0],
                             r.far_off[0], r.far_off[1], r.far_off[2], r.far_off[0]);
  }
};

// box0/box1: the two nodes, 32-byte aligned, in BinaryNode's float layout.
// Returns bit 0 for box0 hit, bit 1 for box1; entry0/entry1 as slab_robust.
HPRT_FORCE_INLINE int slab_robust_pair(const SlabRayPair& r, const float* box0, const float* box1,
                                       float tmin, float tmax, float& entry0, float& entry1) {
  const __m256 a = _mm256_permutevar8x32_ps(_mm256_load_ps(box0), r.perm);
  const __m256 b = _mm256_permutevar8x32_ps(_mm256_load_ps(box1), r.perm);
  const __m256 near_planes = _mm256_permute2f128_ps(a, b, 0x20);
  const __m256 far_planes = _mm256_permute2f128_ps(a, b, 0x31);
  __m256 tn = _mm256_mul_ps(_mm256_sub_ps(near_planes, r.org), r.rcp_near);
  __m256 tf = _mm256_mul_ps(_mm256_sub_ps(far_planes, r.org), r.rcp_far);
  tn = _mm256_max_ps(tn, _mm256_set1_ps(tmin));  // NaN lanes -> tmin
  tf = _mm256_min_ps(tf, _mm256_set1_ps(tmax));  // NaN lanes -> tmax
  tn = _mm256_max_ps(tn, _mm256_permute_ps(tn, 0xB1));
  tn = _mm256_max_ps(tn, _mm256_permute_ps(tn, 0x4E));
  tf = _mm256_min_ps(tf, _mm256_permute_ps(tf, 0xB1));
  tf = _mm256_min_ps(tf, _mm256_permute_ps(tf, 0x4E));
  const int m = _mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ));
  entry0 = _mm256_cvtss_f32(tn);
  entry1 = _mm_cvtss_f32(_mm256_extractf128_ps(tn, 1));
  return (m & 1) | ((m >> 3) & 2);
}
#endif

}  // namespace hprt
