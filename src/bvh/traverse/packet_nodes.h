// What the packet loop (traverse_packet.h) needs of each layout: its root,
// a node's children as NodeRefs with their boxes, prefetching, and for the
// wide layouts the frustum test and the hand-over to single rays.
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
#pragma once

#if defined(__AVX512F__)

#include <immintrin.h>

#include <cstdint>
#include <cstring>

#include "bvh/builders/build_tree.h"
#include "bvh/intersect/leaf_intersect.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/ray_packet.h"
#include "bvh/traverse/traverse_wide.h"
#include "core/force_inline.h"
#include "core/ray.h"

namespace hprt::detail {

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

  AABB bounds() const { return bvh.bounds; }
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

  AABB bounds() const { return bvh.bounds(); }
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

}  // namespace hprt::detail

#endif  // __AVX512F__
