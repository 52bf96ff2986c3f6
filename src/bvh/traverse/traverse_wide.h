// Closest-hit and any-hit traversal of the wide layout (WideBvh<N>): the ray
// is tested against all N child boxes of a node at once (slab_wide); one hit
// child is entered directly, two are ordered near first with the far one
// pushed, more are pushed and sorted so the nearest is on top and entered
// (Embree's BVHNIntersector1 orders children the same way); any-hit queries
// skip that sort. Stack entries
// carry their entry distance, so popped nodes beyond the closest hit are
// skipped. The leaf test and its (tnear, tfar] rule are traverse()'s
// (intersect_leaf), so both layouts find the same hits.
#pragma once

#include <cstdint>

#include "bvh/builders/build_tree.h"
#include "bvh/intersect/ray_box_wide.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/traverse_bvh2.h"
#include "bvh/traverse/wide_child_order.h"
#include "core/prefetch.h"

namespace hprt {

namespace detail {
template <int N>
HPRT_FORCE_INLINE void prefetch_node(const WideNode<N>* node) {
  prefetch_aligned(node);
}

// One inner node of a closest-hit or any-hit traversal: tests the ray
// against its children, pushes the hit ones it does not enter (ordered as
// the file's comment says) and returns the one to enter next, or an empty
// ref when no child is hit (the caller pops). kPrefetchChildren requests
// every hit child's lines (a single ray waits for the one it enters next
// anyway; traverse_interleaved.h prefetches only that one, early).
template <typename Test, bool kAnyHit, bool kPrefetchChildren, int N>
HPRT_FORCE_INLINE NodeRef visit_wide_node(const WideBvh<N>& bvh, const WideNode<N>& node,
                                          const WideSlabRay& slab, float tnear, float tfar,
                                          WideStackEntry* stack, int& sp) {
  alignas(32) float dist[N];
  const unsigned all = slab_wide<N>(slab, node, tnear, tfar, dist);
  unsigned mask = all;
  if constexpr (kPrefetchChildren)
    for (unsigned m = mask; m; m &= m - 1) {
      const NodeRef c = node.child[__builtin_ctz(m)];
      if (c.is_leaf())
        Test::prefetch(bvh.triangles, c.leaf_range());
      else
        prefetch_node(&bvh.nodes[c.index()]);
    }
  if (mask == 0) return NodeRef{};
  const int i0 = __builtin_ctz(mask);
  mask &= mask - 1;
  if (mask == 0) return node.child[i0];
  const int i1 = __builtin_ctz(mask);
  mask &= mask - 1;
  if (mask == 0) {
    const bool first_near = dist[i0] <= dist[i1];
    const int near = first_near ? i0 : i1, far = first_near ? i1 : i0;
    stack[sp++] = {node.child[far].bits, dist[far]};
    return node.child[near];
  }
  if constexpr (kAnyHit) {
    // Any hit ends the query, so no order is worth sorting for (as
    // Embree's occluded traversal): enter the first, push the rest.
    stack[sp++] = {node.child[i1].bits, dist[i1]};
    for (; mask; mask &= mask - 1) {
      const int i = __builtin_ctz(mask);
      stack[sp++] = {node.child[i].bits, dist[i]};
    }
    return node.child[i0];
  }
  // Three or more: push all so that entry distances decrease towards the
  // top, enter the nearest (wide_child_order.h).
  return push_children_sorted<N>(node, dist, all, stack, sp);
}

// The next stack entry that may still hold a hit closer than tfar, or an
// empty ref when none is left.
HPRT_FORCE_INLINE NodeRef pop_closer(const WideStackEntry* stack, int& sp, float tfar) {
  while (sp > 0) {
    const WideStackEntry& e = stack[--sp];
    if (e.entry <= tfar) return NodeRef{e.ref};
  }
  return NodeRef{};
}
}  // namespace detail

// The traversal loop from node `start` (the root, or a node a packet hands
// over to one of its rays, traverse_packet.h) with the ray's tfar and closest
// hit so far, both updated. With kAnyHit it returns true at the first hit
// (recorded in `closest`); otherwise false, the answer being in `closest`.
template <typename Test, bool kAnyHit, int N, bool kStats = false>
HPRT_FORCE_INLINE bool traverse_wide_from(const WideBvh<N>& bvh, NodeRef start,
                                          const WideSlabRay& slab,
                                          const typename Test::Prepared& prep, float tnear,
                                          float& tfar, ClosestHit& closest,
                                          TraversalStats* stats = nullptr) {
  detail::WideStackEntry stack[detail::kWideStackSize<N>];
  int sp = 0;
  NodeRef cur = start;
  for (;;) {
    while (cur.is_inner()) {
      if constexpr (kStats) ++stats->nodes;
      cur = detail::visit_wide_node<Test, kAnyHit, true>(bvh, bvh.nodes[cur.index()], slab, tnear,
                                                         tfar, stack, sp);
    }
    if (cur.is_leaf() && intersect_leaf<Test, kAnyHit, kStats>(
                             prep, bvh.triangles, cur.leaf_range(), tnear, tfar, closest, stats))
      return true;
    cur = detail::pop_closer(stack, sp, tfar);
    if (cur.empty()) return false;
  }
}

// Same contract as traverse() (`answer` included): the ray must be valid
// (ray_is_valid).
template <typename Test, bool kAnyHit, int N, bool kStats = false>
bool traverse_wide(const WideBvh<N>& bvh, const Ray& ray, Hit& hit, TraversalStats* stats = nullptr,
                   ClosestHit* answer = nullptr) {
  if (bvh.empty()) return false;
  const WideSlabRay slab(ray);
  const typename Test::Prepared prep = Test::prepare(ray, bvh.bounds);
  float tfar = ray.tfar;
  ClosestHit closest;
  traverse_wide_from<Test, kAnyHit, N, kStats>(bvh, bvh.root, slab, prep, ray.tnear, tfar, closest,
                                               stats);
  if (answer)
    *answer = closest;
  else if (closest.found)
    closest.store(bvh.triangles, hit);
  return closest.found;
}

}  // namespace hprt
