// A packet of 16 rays as AVX-512 lanes and its box test: per lane, exactly
// slab_robust()'s (the lane's own octant picks the near and far planes, each
// with its padded reciprocal, NaN slab values dropped), so a lane enters the
// boxes its ray would alone. Holds each lane's triangle-test state, set up on
// the first leaf the lane reaches, and the packet's frustum (packet_nodes.h).
#pragma once

#if defined(__AVX512F__)

#include <immintrin.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "bvh/intersect/ray_box.h"
#include "bvh/intersect/ray_triangle_lanes.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/simd16.h"
#include "core/force_inline.h"
#include "core/ray.h"
#include "core/ray_fields16.h"

namespace hprt {

inline constexpr int kPacketSize = 16;

namespace detail {

// The packet's rays as lanes: SlabRay's fields, the interval, and each lane's
// triangle-test state.
template <typename Test>
struct RayPacket {
  __m512 org[3], rcp_near[3], rcp_far[3];
  __mmask16 neg[3];  // direction sign bit set: the near plane is the box maximum
  // When every lane has the same direction signs (camera packets nearly
  // always), each axis' near and far plane as a box row (2 * axis + 1 = the
  // maximum), so no per-lane select is needed.
  bool same_octant = false;
  int near_row[3] = {0, 2, 4}, far_row[3] = {1, 3, 5};
  __m512 tnear;
  alignas(64) float tnear_lane[kPacketSize];
  alignas(64) float tfar_lane[kPacketSize];  // the rays' tfar, for the traversal to shrink
  // The frustum (same_octant and finite reciprocals only): per axis the
  // origin extreme at which the near-plane distances are least and the one
  // at which the far-plane distances are greatest, the reciprocals' ranges,
  // and the least tnear.
  bool frustum = false;
  float near_org[3], far_org[3], rcp_near_lo[3], rcp_near_hi[3], rcp_far_lo[3], rcp_far_hi[3];
  float tnear_min = 0.0f;
  // Each lane's state is set at its first leaf (`prepared`): most rays of a
  // packet that misses the mesh never get there. A variant member is left
  // uninitialised by the constructor, where a plain array would run
  // Prepared's member initialisers for all 16 lanes of every packet.
  union {
    typename Test::Prepared prep[kPacketSize];
  };

  const Ray* rays;
  AABB root;               // the tree's box, for the lanes' error bound (WatertightTest::prepare)
  __mmask16 prepared = 0;  // lanes whose `prep` is set (on their first leaf)
  // The watertight test over all lanes at once, set up with every lane's
  // `prep` at the first leaf (usable when the lanes share their axes).
  static constexpr bool kLaneTest = std::is_same_v<Test, WatertightTest>;
  // Default-initialised (its vectors are set by setup()): `{}` would zero them.
  std::conditional_t<kLaneTest, WatertightLanes, bool> lanes;

  HPRT_FORCE_INLINE RayPacket(const Ray* r, const AABB& root_box) : rays(r), root(root_box) {
    __m512 field[8];
    load_ray_fields16(rays, field);
    tnear = field[3];
    _mm512_store_ps(tnear_lane, tnear);
    _mm512_store_ps(tfar_lane, field[7]);
    for (int a = 0; a < 3; ++a) {
      const __m512 dir = field[4 + a];
      org[a] = field[a];
      const __m512 rcp = _mm512_div_ps(_mm512_set1_ps(1.0f), dir);  // correctly rounded
      rcp_near[a] = _mm512_mul_ps(rcp, _mm512_set1_ps(kSlabNearPad));
      rcp_far[a] = _mm512_mul_ps(rcp, _mm512_set1_ps(kSlabFarPad));
      neg[a] = _mm512_cmplt_epi32_mask(_mm512_castps_si512(dir), _mm512_setzero_si512());
    }
    same_octant = true;
    for (int a = 0; a < 3; ++a) {
      same_octant = same_octant && (neg[a] == 0 || neg[a] == 0xFFFF);
      const int is_neg = neg[a] ? 1 : 0;
      near_row[a] = 2 * a + is_neg;
      far_row[a] = 2 * a + 1 - is_neg;
    }
    if (same_octant) setup_frustum();
  }

  void setup_frustum() {
    const __m512 inf = _mm512_set1_ps(std::numeric_limits<float>::infinity());
    for (int a = 0; a < 3; ++a) {
      // Finite reciprocals: no inf * 0 (NaN) in the bounds, which the lane
      // test drops for its own lane but the frustum could not.
      if (_mm512_cmp_ps_mask(_mm512_abs_ps(rcp_near[a]), inf, _CMP_LT_OQ) != 0xFFFF ||
          _mm512_cmp_ps_mask(_mm512_abs_ps(rcp_far[a]), inf, _CMP_LT_OQ) != 0xFFFF)
        return;
    }
    for (int a = 0; a < 3; ++a) {
      // plane - org is least at the greatest origin: with a positive
      // reciprocal the near distance is least there, with a negative one at
      // the least origin (the far distance greatest the other way round).
      const float lo = reduce_min16(org[a]), hi = reduce_max16(org[a]);
      near_org[a] = neg[a] ? lo : hi;
      far_org[a] = neg[a] ? hi : lo;
      rcp_near_lo[a] = reduce_min16(rcp_near[a]);
      rcp_near_hi[a] = reduce_max16(rcp_near[a]);
      rcp_far_lo[a] = reduce_min16(rcp_far[a]);
      rcp_far_hi[a] = reduce_max16(rcp_far[a]);
    }
    tnear_min = reduce_min16(tnear);
    frustum = true;
  }

  // Triangle-test state for the lanes of `lanes`: most rays of a packet that
  // misses the mesh never reach a leaf.
  HPRT_FORCE_INLINE void prepare(__mmask16 wanted) {
    if constexpr (kLaneTest) {
      // All lanes at once, with one lane error bound for the packet's
      // origins (valid for each lane: it bounds every lane's own).
      if (prepared == 0xFFFF) return;
      const Vec3f lo{reduce_min16(org[0]), reduce_min16(org[1]), reduce_min16(org[2])};
      const Vec3f hi{reduce_max16(org[0]), reduce_max16(org[1]), reduce_max16(org[2])};
      const double bound = WatertightTest::lane_bound(lo, hi, root);
      for (int l = 0; l < kPacketSize; ++l) {
        prep[l] = Test::prepare(rays[l]);
        prep[l].lane_bound = bound;
      }
      lanes.setup(prep, tnear_lane);
      prepared = 0xFFFF;
      return;
    }
    for (unsigned m = wanted & ~prepared; m; m &= m - 1) {
      const int l = __builtin_ctz(m);
      prep[l] = Test::prepare(rays[l], root);
    }
    prepared |= wanted;
  }
};

// A child box as rows: plane(2 * axis) is its minimum on that axis,
// plane(2 * axis + 1) its maximum.
template <int N>
struct WideSlot {
  const WideNode<N>& node;
  int i;
  float plane(int row) const { return node.bounds[row][i]; }
};
struct BinaryBox {
  const BinaryNode& node;
  float plane(int row) const { return (row & 1) ? node.max[row >> 1] : node.min[row >> 1]; }
};

// slab_robust() per lane against `box`: the lanes of `active` whose ray
// overlaps it on [tnear, tfar]; entry = max(tnear, entry distance) per lane.
template <typename Test, typename Box>
HPRT_FORCE_INLINE __mmask16 slab_packet(const RayPacket<Test>& p, const Box& box, __m512 tfar,
                                        __mmask16 active, __m512& entry) {
  __m512 tn[3], tf[3];
  for (int a = 0; a < 3; ++a) {
    __m512 near_plane, far_plane;
    if (p.same_octant) {
      near_plane = _mm512_set1_ps(box.plane(p.near_row[a]));
      far_plane = _mm512_set1_ps(box.plane(p.far_row[a]));
    } else {
      const __m512 lo = _mm512_set1_ps(box.plane(2 * a));
      const __m512 hi = _mm512_set1_ps(box.plane(2 * a + 1));
      near_plane = _mm512_mask_blend_ps(p.neg[a], lo, hi);
      far_plane = _mm512_mask_blend_ps(p.neg[a], hi, lo);
    }
    tn[a] = _mm512_mul_ps(_mm512_sub_ps(near_plane, p.org[a]), p.rcp_near[a]);
    tf[a] = _mm512_mul_ps(_mm512_sub_ps(far_plane, p.org[a]), p.rcp_far[a]);
  }
  const __m512 t0 = max16(tn[0], max16(tn[1], max16(tn[2], p.tnear)));
  const __m512 t1 = min16(tf[0], min16(tf[1], min16(tf[2], tfar)));
  entry = t0;
  return _mm512_mask_cmp_ps_mask(active, t0, t1, _CMP_LE_OQ);
}

}  // namespace detail
}  // namespace hprt

#endif  // __AVX512F__
