// Packet traversal of every layout (binary, 4- and 8-wide) for coherent rays
// (camera rays, and the shadow and mirror rays of neighbouring pixels): 16
// rays go down the tree together, one AVX-512 lane per ray, so each node is
// fetched once for all of them and each of its child boxes is tested against
// the 16 rays in one pass (Wald, Slusallek, Benthin & Wagner, "Interactive
// Rendering with Coherent Ray Tracing", EG 2001; Embree's rtcIntersect16).
// The loop is written once; PacketNodes<Bvh> gives it a layout's root and
// children (as NodeRefs) and their boxes.
//
// Per lane, every operation is the single-ray one: the child box test is
// slab_robust()'s (the lane's own octant picks the near and far planes, each
// with its padded reciprocal, NaN slab values dropped) and the
// leaf runs the same triangle test with the lane's own Prepared state and
// interval. Children are entered nearest first by their smallest entry
// distance over the packet's lanes; a stack entry keeps every lane's entry
// distance, so a popped node only goes on with the lanes whose closest hit is
// not already nearer. Lanes take part in a node only if their own ray hits its
// box, so each ray tests the triangles it would alone, maybe in another order;
// the closest hit is the smallest (t, leaf index) either way (leaf_intersect.h
// breaks ties by leaf index), so a packet answers exactly as its rays traced
// one by one. In the wide layouts a node that at most kHybridSwitch lanes
// enter is handed to those lanes' rays one by one (traverse_wide_from, with
// the lane's tfar and closest hit so far), which changes nothing in the answers.
//
// Before a wide node's children are tested lane by lane, all of them are
// tested at once against the packet's frustum (Reshetov, Soupikov & Hurley,
// "Multi-Level Ray Tracing Algorithm", SIGGRAPH 2005; Embree's
// intersectNodeFrustum): per axis, bounds on every lane's slab distances
// from the lanes' extreme origins and padded reciprocals. Rounding is
// monotone, so each bound is the float value of a lane's own formula at an
// extreme of its inputs, never nearer (far plane: never farther) than any
// lane's: a child the frustum culls is one no lane enters, and the answers
// stay the lane test's. Most children that camera and shadow packets miss
// are culled so. Used only where every lane has the same direction signs and
// finite reciprocals.
//
// Built only where AVX-512F is available (HPRT_HAS_PACKETS); the backend
// traces rays one by one elsewhere.
#pragma once

#if defined(__AVX512F__)
#define HPRT_HAS_PACKETS 1

#include <immintrin.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "bvh/builders/build_tree.h"
#include "bvh/intersect/leaf_intersect.h"
#include "bvh/intersect/ray_box.h"
#include "bvh/intersect/ray_triangle_lanes.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/traverse_wide.h"
#include "core/force_inline.h"
#include "core/hit.h"
#include "core/ray.h"

namespace hprt {

inline constexpr int kPacketSize = 16;
// Hybrid traversal (Benthin, Wald, Woop, Ernst & Mark, "Combining Single and
// Packet-Ray Tracing for Arbitrary Ray Distributions on the Intel MIC
// Architecture", TVCG 2012; Embree's BVHNIntersectorKHybrid): at a node that
// only this many lanes still enter, each of them goes on alone
// (traverse_wide_from), testing one ray against all children at once instead
// of 16 lanes child by child. Two, as Embree's switch for coherent packets.
inline constexpr int kHybridSwitch = 2;
#if defined(HPRT_HAS_LEAF_LANES)
inline constexpr bool kLeafLanes = true;
#else
inline constexpr bool kLeafLanes = false;
#endif

namespace detail {

// _mm512_max_ps / _mm512_min_ps without their undefined pass-through operand,
// which g++ 12 reports as maybe-uninitialized. Per lane `a > b ? a : b` and
// `a < b ? a : b`: robust_max / robust_min with the slab value first.
HPRT_FORCE_INLINE __m512 max16(__m512 a, __m512 b) { return _mm512_mask_max_ps(b, 0xFFFF, a, b); }
HPRT_FORCE_INLINE __m512 min16(__m512 a, __m512 b) { return _mm512_mask_min_ps(b, 0xFFFF, a, b); }

// The smallest of the lanes of `m` (+inf for none), by shuffles (the mask
// variants, for the same reason as above); the greatest (-inf for none).
HPRT_FORCE_INLINE float masked_min16(__mmask16 m, __m512 v) {
  v = _mm512_mask_mov_ps(_mm512_set1_ps(std::numeric_limits<float>::infinity()), m, v);
  v = min16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0x4E));
  v = min16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0xB1));
  v = min16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0x4E));
  v = min16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0xB1));
  return _mm512_cvtss_f32(v);
}
HPRT_FORCE_INLINE float masked_max16(__mmask16 m, __m512 v) {
  v = _mm512_mask_mov_ps(_mm512_set1_ps(-std::numeric_limits<float>::infinity()), m, v);
  v = max16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0x4E));
  v = max16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0xB1));
  v = max16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0x4E));
  v = max16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0xB1));
  return _mm512_cvtss_f32(v);
}
// The least and the greatest lane.
HPRT_FORCE_INLINE float reduce_min16(__m512 v) { return masked_min16(0xFFFF, v); }
HPRT_FORCE_INLINE float reduce_max16(__m512 v) { return masked_max16(0xFFFF, v); }

// _mm512_i32gather_ps without its undefined pass-through operand, which
// g++ 12 reports as maybe-uninitialized (as max16 above).
HPRT_FORCE_INLINE __m512 gather16(__m512i offset, const float* base) {
  return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xFFFF, offset, base, 4);
}

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
  typename Test::Prepared prep[kPacketSize];

  const Ray* rays;
  __mmask16 prepared = 0;  // lanes whose `prep` is set (on their first leaf)
  // The watertight test over all lanes at once, set up with every lane's
  // `prep` at the first leaf (usable when the lanes share their axes).
  static constexpr bool kLaneTest = std::is_same_v<Test, WatertightTest>;
  std::conditional_t<kLaneTest, WatertightLanes, bool> lanes{};

  HPRT_FORCE_INLINE explicit RayPacket(const Ray* r) : rays(r) {
    // A Ray is eight floats (org, tnear, dir, tfar): field f of lane l is
    // float 8 * l + f from the first ray.
    static_assert(sizeof(Ray) == 8 * sizeof(float) && offsetof(Ray, tnear) == 3 * sizeof(float) &&
                  offsetof(Ray, dir) == 4 * sizeof(float) &&
                  offsetof(Ray, tfar) == 7 * sizeof(float));
    const __m512i lane_offset = _mm512_slli_epi32(
        _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), 3);
    const float* field = reinterpret_cast<const float*>(rays);
    tnear = gather16(lane_offset, field + 3);
    _mm512_store_ps(tnear_lane, tnear);
    _mm512_store_ps(tfar_lane, gather16(lane_offset, field + 7));
    for (int a = 0; a < 3; ++a) {
      const __m512 dir = gather16(lane_offset, field + 4 + a);
      org[a] = gather16(lane_offset, field + a);
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
    if constexpr (kLaneTest) wanted = 0xFFFF;
    for (unsigned m = wanted & ~prepared; m; m &= m - 1) {
      const int l = __builtin_ctz(m);
      prep[l] = Test::prepare(rays[l]);
    }
    if constexpr (kLaneTest)
      if (prepared != 0xFFFF) lanes.setup(prep, tnear_lane);
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

// One float per slot of a wide node's box rows (the frustum test), as a GCC
// vector: arithmetic and comparisons by operator, on either width.
template <int N>
struct SlotVector {
  typedef float V __attribute__((vector_size(N * sizeof(float))));
  static V set1(float x) { return V{} + x; }
  static V load(const float* x) {
    V v;
    std::memcpy(&v, x, sizeof v);
    return v;
  }
  // As _mm_min_ps / _mm_max_ps (no NaN reaches them).
  static V min(V a, V b) { return a < b ? a : b; }
  static V max(V a, V b) { return a > b ? a : b; }
  // The slots where a <= b, as bits.
  static unsigned le(V a, V b) {
    const V mask = reinterpret_cast<V>(a <= b);
    if constexpr (N == 8)
      return unsigned(_mm256_movemask_ps(reinterpret_cast<__m256>(mask)));
    else
      return unsigned(_mm_movemask_ps(reinterpret_cast<__m128>(mask)));
  }
};

// What the packet loop needs of a layout, with children named by NodeRef
// (inner: the node whose children are tested next; leaf: its triangle range).
template <typename Bvh>
struct PacketNodes;

template <int N>
struct PacketNodes<WideBvh<N>> {
  static constexpr int kMaxChildren = N;
  static constexpr int kStackSize = 1 + (N - 1) * kMaxBuildDepth;
  const WideBvh<N>& bvh;

  // The root, and the lanes that enter it (the wide root has no box).
  template <typename Test>
  NodeRef root(const RayPacket<Test>&, __m512, __mmask16& lanes) const {
    lanes = 0xFFFF;
    return bvh.root;
  }
  // f(box, child ref, slot) for each child of inner node `n` whose slot is
  // in `slots`.
  template <typename F>
  HPRT_FORCE_INLINE void for_each_child(NodeRef n, unsigned slots, F&& f) const {
    const WideNode<N>& node = bvh.nodes[n.index()];
    for (unsigned m = slots; m; m &= m - 1) {
      const int i = __builtin_ctz(m);
      if (node.child[i].empty()) break;  // children fill the first slots
      f(WideSlot<N>{node, i}, node.child[i], i);
    }
  }
  // The slots of `n` whose box the packet's frustum overlaps on
  // [tnear_min, tfar_max]; all of them without a frustum.
  template <typename Test>
  HPRT_FORCE_INLINE unsigned frustum_slots(NodeRef n, const RayPacket<Test>& p,
                                           float tfar_max) const {
    if (!p.frustum) return (1u << N) - 1;
    const WideNode<N>& node = bvh.nodes[n.index()];
    using V = SlotVector<N>;
    auto t0 = V::set1(p.tnear_min), t1 = V::set1(tfar_max);
    for (int a = 0; a < 3; ++a) {
      // Which reciprocal extreme bounds a product depends on the sign of
      // the other factor: both products, the least (greatest) kept.
      const auto near = V::load(node.bounds[p.near_row[a]]) - p.near_org[a];
      const auto far = V::load(node.bounds[p.far_row[a]]) - p.far_org[a];
      t0 = V::max(t0, V::min(near * p.rcp_near_lo[a], near * p.rcp_near_hi[a]));
      t1 = V::min(t1, V::max(far * p.rcp_far_lo[a], far * p.rcp_far_hi[a]));
    }
    return V::le(t0, t1);
  }
  HPRT_FORCE_INLINE void prefetch_inner(NodeRef c) const { prefetch_node(&bvh.nodes[c.index()]); }

  // Hybrid traversal: a packet down to a few lanes hands each lane's ray the
  // subtree at `start` (traverse_wide_from).
  static constexpr bool kHandsOver = true;
  template <typename Test, bool kAnyHit>
  HPRT_FORCE_INLINE bool trace_lane(NodeRef start, const Ray& ray,
                                    const typename Test::Prepared& prep, float tnear, float& tfar,
                                    ClosestHit& closest) const {
    return traverse_wide_from<Test, kAnyHit, N>(bvh, start, WideSlabRay(ray), prep, tnear, tfar,
                                                closest);
  }
};

template <>
struct PacketNodes<Bvh2> {
  static constexpr int kMaxChildren = 2;
  static constexpr int kStackSize = 1 + kMaxBuildDepth;
  const Bvh2& bvh;

  static NodeRef ref_of(const BinaryNode& node, uint32_t index) {
    return node.is_leaf() ? NodeRef::leaf(node.index, node.count) : NodeRef::inner(index);
  }
  // The root, and the lanes that hit its box.
  template <typename Test>
  NodeRef root(const RayPacket<Test>& p, __m512 tfar, __mmask16& lanes) const {
    __m512 entry;
    lanes = slab_packet(p, BinaryBox{bvh.nodes[0]}, tfar, 0xFFFF, entry);
    return ref_of(bvh.nodes[0], 0);
  }
  template <typename F>
  HPRT_FORCE_INLINE void for_each_child(NodeRef n, unsigned, F&& f) const {
    const uint32_t first = bvh.nodes[n.index()].index;  // children are adjacent
    for (uint32_t k = 0; k < 2; ++k)
      f(BinaryBox{bvh.nodes[first + k]}, ref_of(bvh.nodes[first + k], first + k), int(k));
  }
  // No frustum here: two children are tested lane by lane straight away.
  template <typename Test>
  static unsigned frustum_slots(NodeRef, const RayPacket<Test>&, float) {
    return 3u;
  }
  // The child pair of inner node c: one 64-byte line.
  HPRT_FORCE_INLINE void prefetch_inner(NodeRef c) const {
    __builtin_prefetch(&bvh.nodes[bvh.nodes[c.index()].index]);
  }

  static constexpr bool kHandsOver = false;
  template <typename Test, bool kAnyHit>
  bool trace_lane(NodeRef, const Ray&, const typename Test::Prepared&, float, float&,
                  ClosestHit&) const {
    return false;
  }
};

struct alignas(64) PacketStackEntry {
  __m512 entry;
  uint64_t ref;
  __mmask16 lanes;  // the lanes that hit the node
};

}  // namespace detail

// Traces rays[0..16), all valid (ray_is_valid). Closest hit: hits[l] is set for
// every lane (a miss is Hit{}). Any hit: occluded[l] is 1 or 0. `hits` is used
// only without kAnyHit, `occluded` only with it.
template <typename Test, bool kAnyHit, typename Bvh>
void traverse_packet(const Bvh& bvh, const Ray* rays, Hit* hits, uint8_t* occluded) {
  using Nodes = detail::PacketNodes<Bvh>;
  constexpr int N = Nodes::kMaxChildren;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  ClosestHit closest[kPacketSize];
  if (bvh.empty()) {
    for (int l = 0; l < kPacketSize; ++l) {
      if constexpr (kAnyHit)
        occluded[l] = 0;
      else
        hits[l] = Hit{};
    }
    return;
  }
  const Nodes layout{bvh};
  const LeafTriangles& tris = bvh.triangles;
  detail::RayPacket<Test> packet(rays);
  float* const tfar_lane = packet.tfar_lane;
  __m512 tfar = _mm512_load_ps(tfar_lane);
  float tfar_max = detail::reduce_max16(tfar);  // over every lane: bounds the active ones
  __mmask16 done = 0;                           // any hit: lanes already occluded

  detail::PacketStackEntry stack[Nodes::kStackSize];
  int sp = 0;
  __mmask16 active = 0;
  NodeRef cur = layout.root(packet, tfar, active);
  if (!active) cur = NodeRef{};
  for (;;) {
    while (cur.is_inner()) {
      if constexpr (Nodes::kHandsOver) {
        if (__builtin_popcount(active) <= kHybridSwitch) {
          packet.prepare(active);
          for (unsigned m = active; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            if (layout.template trace_lane<Test, kAnyHit>(
                    cur, rays[l], packet.prep[l], packet.tnear_lane[l], tfar_lane[l], closest[l])) {
              tfar_lane[l] = -kInf;  // occluded: this lane is done
              done |= __mmask16(1u << l);
            }
          }
          tfar = _mm512_load_ps(tfar_lane);
          tfar_max = detail::reduce_max16(tfar);
          cur = NodeRef{};
          break;
        }
      }
      __m512 entry[N];
      float key[N];
      __mmask16 hit[N];
      NodeRef child[N];
      int order[N];
      int count = 0;
      const unsigned slots = layout.frustum_slots(cur, packet, tfar_max);
      layout.for_each_child(cur, slots, [&](const auto& box, NodeRef c, int i) {
        child[i] = c;
        hit[i] = detail::slab_packet(packet, box, tfar, active, entry[i]);
        if (hit[i]) {
          if (c.is_leaf())
            Test::prefetch(tris, c.leaf_range());
          else
            layout.prefetch_inner(c);
          order[count++] = i;
        }
      });
      if (count == 0) {
        cur = NodeRef{};
        break;
      }
      if (!kAnyHit && count > 1) {
        // Nearest first: insertion sort of at most N keys.
        for (int k = 0; k < count; ++k)
          key[order[k]] = detail::masked_min16(hit[order[k]], entry[order[k]]);
        for (int a = 1; a < count; ++a) {
          const int o = order[a];
          int b = a;
          for (; b > 0 && key[order[b - 1]] > key[o]; --b) order[b] = order[b - 1];
          order[b] = o;
        }
      }
      for (int k = count - 1; k > 0; --k) {
        const int i = order[k];
        stack[sp].entry = entry[i];
        stack[sp].ref = child[i].bits;
        stack[sp].lanes = hit[i];
        ++sp;
      }
      cur = child[order[0]];
      active = hit[order[0]];
    }
    if (cur.is_leaf()) {
      packet.prepare(active);
      const LeafRange leaf = cur.leaf_range();
      const uint32_t end = leaf.first + leaf.count;
      bool all_lanes = false;
      if constexpr (detail::RayPacket<Test>::kLaneTest) {
        // One triangle on the lanes of the rays, or each ray on the lanes
        // of the triangles (leaf_intersect.h), whichever is fewer tests.
        const int halves = ((active & 0xFF) != 0) + ((active >> 8) != 0);
        all_lanes = packet.lanes.usable() &&
                    (!kLeafLanes || __builtin_popcount(active) >= int(leaf.count) * halves);
        alignas(64) float t[kPacketSize], u[kPacketSize], v[kPacketSize];
        for (uint32_t i = leaf.first; i < end && active && all_lanes; ++i) {
          const __mmask16 h = packet.lanes.intersect(tris, leaf, i, tfar_lane, active, t, u, v);
          for (unsigned m = h; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            if (!kAnyHit && closest[l].loses_tie(i, t[l])) continue;
            closest[l].found = true;
            closest[l].index = i;
            closest[l].best = TriangleHit{t[l], u[l], v[l]};
            tfar_lane[l] = kAnyHit ? -kInf : t[l];
            if constexpr (kAnyHit) {
              done |= __mmask16(1u << l);
              active &= __mmask16(~(1u << l));
            }
          }
        }
      }
      // Lanes whose rays differ in axes: each lane's own leaf test.
      for (unsigned m = all_lanes ? 0u : unsigned(active); m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (intersect_leaf<Test, kAnyHit, false>(packet.prep[l], tris, leaf, packet.tnear_lane[l],
                                                 tfar_lane[l], closest[l], nullptr)) {
          tfar_lane[l] = -kInf;  // occluded: this lane is done
          done |= __mmask16(1u << l);
          active &= __mmask16(~(1u << l));
        }
      }
      if constexpr (kAnyHit)
        if (done == 0xFFFF) break;
      tfar = _mm512_load_ps(tfar_lane);
      tfar_max = detail::reduce_max16(tfar);
    }
    // Pop the next entry that may still hold a closer hit for some lane.
    active = 0;
    while (sp > 0 && !active) {
      --sp;
      active = _mm512_mask_cmp_ps_mask(stack[sp].lanes, stack[sp].entry, tfar, _CMP_LE_OQ);
    }
    if (!active) break;
    cur = NodeRef{stack[sp].ref};
  }
  for (int l = 0; l < kPacketSize; ++l) {
    if constexpr (kAnyHit) {
      occluded[l] = (done >> l) & 1;
    } else {
      hits[l] = Hit{};
      if (closest[l].found) closest[l].store(tris, hits[l]);
    }
  }
}

}  // namespace hprt

#endif  // __AVX512F__
