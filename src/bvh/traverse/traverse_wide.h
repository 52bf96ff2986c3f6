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

namespace hprt {

namespace detail {
// Plain data (no NodeRef default member), so the stack array is left
// uninitialised: it is large (N = 8: 449 entries) and set per ray.
struct WideStackEntry {
  uint64_t ref;
  float entry;
};

template <int N>
inline void prefetch_node(const WideNode<N>* node) {
  const char* p = reinterpret_cast<const char*>(node);
  for (int line = 0; line < int(sizeof(WideNode<N>)); line += 64) __builtin_prefetch(p + line);
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
  const WideNode<N>* nodes = bvh.nodes.data();
  const LeafTriangles& tris = bvh.triangles;

  // Each wide level pushes at most N - 1 entries and the tree is no deeper
  // than the binary tree it was collapsed from.
  detail::WideStackEntry stack[1 + (N - 1) * kMaxBuildDepth];
  int sp = 0;
  NodeRef cur = start;
  for (;;) {
    while (cur.is_inner()) {
      if constexpr (kStats) ++stats->nodes;
      const WideNode<N>& node = nodes[cur.index()];
      alignas(32) float dist[N];
      unsigned mask = slab_wide<N>(slab, node, tnear, tfar, dist);
      for (unsigned m = mask; m; m &= m - 1) {
        const int i = __builtin_ctz(m);
        const NodeRef c = node.child[i];
        if (c.is_leaf())
          Test::prefetch(tris, c.leaf_range());
        else
          detail::prefetch_node(&nodes[c.index()]);
      }
      if (mask == 0) {
        cur = NodeRef{};
        break;
      }
      const int i0 = __builtin_ctz(mask);
      mask &= mask - 1;
      if (mask == 0) {
        cur = node.child[i0];
        continue;
      }
      const int i1 = __builtin_ctz(mask);
      mask &= mask - 1;
      if (mask == 0) {
        const bool first_near = dist[i0] <= dist[i1];
        const int near = first_near ? i0 : i1, far = first_near ? i1 : i0;
        stack[sp++] = {node.child[far].bits, dist[far]};
        cur = node.child[near];
        continue;
      }
      if constexpr (kAnyHit) {
        // Any hit ends the query, so no order is worth sorting for (as
        // Embree's occluded traversal): enter the first, push the rest.
        stack[sp++] = {node.child[i1].bits, dist[i1]};
        for (; mask; mask &= mask - 1) {
          const int i = __builtin_ctz(mask);
          stack[sp++] = {node.child[i].bits, dist[i]};
        }
        cur = node.child[i0];
        continue;
      }
      // Three or more: push all, insertion-sort the pushed run so entry
      // distances decrease towards the top, enter the nearest.
      const int base = sp;
      stack[sp++] = {node.child[i0].bits, dist[i0]};
      stack[sp++] = {node.child[i1].bits, dist[i1]};
      for (; mask; mask &= mask - 1) {
        const int i = __builtin_ctz(mask);
        stack[sp++] = {node.child[i].bits, dist[i]};
      }
      for (int a = base + 1; a < sp; ++a) {
        const detail::WideStackEntry e = stack[a];
        int b = a;
        for (; b > base && stack[b - 1].entry < e.entry; --b) stack[b] = stack[b - 1];
        stack[b] = e;
      }
      cur = NodeRef{stack[--sp].ref};
    }
    if (cur.is_leaf() && intersect_leaf<Test, kAnyHit, kStats>(prep, tris, cur.leaf_range(), tnear,
                                                               tfar, closest, stats))
      return true;
    // Pop the next entry that may still hold a closer hit.
    for (;;) {
      if (sp == 0) return false;
      const detail::WideStackEntry e = stack[--sp];
      if (e.entry <= tfar) {
        cur = NodeRef{e.ref};
        break;
      }
    }
  }
}

// Same contract as traverse(): the ray must be valid (ray_is_valid).
template <typename Test, bool kAnyHit, int N, bool kStats = false>
bool traverse_wide(const WideBvh<N>& bvh, const Ray& ray, Hit& hit,
                   TraversalStats* stats = nullptr) {
  if (bvh.empty()) return false;
  const WideSlabRay slab(ray);
  const typename Test::Prepared prep = Test::prepare(ray, bvh.bounds);
  float tfar = ray.tfar;
  ClosestHit closest;
  traverse_wide_from<Test, kAnyHit, N, kStats>(bvh, bvh.root, slab, prep, ray.tnear, tfar, closest,
                                               stats);
  if (closest.found) closest.store(bvh.triangles, hit);
  return closest.found;
}

}  // namespace hprt
