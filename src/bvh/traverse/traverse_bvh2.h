// Closest-hit and any-hit traversal of the binary layout (the report's
// Algorithm 7): stack based, both children's boxes tested together, the nearer
// visited first and the farther pushed with its entry distance, popped nodes
// skipped once they start beyond the closest hit. Written once, templated on
// the triangle test; stats counters compile out (`if constexpr`).
#pragma once

#include <cstdint>

#include "bvh/intersect/leaf_intersect.h"
#include "bvh/intersect/ray_box.h"
#include "bvh/intersect/ray_triangle.h"
#include "bvh/layout/bvh2.h"
#include "bvh/traverse/traversal_stack.h"
#include "core/hit.h"
#include "core/ray.h"

namespace hprt {

// Rays that hprt defines as misses (core/ray.h), checked once before traversal.
inline bool ray_is_valid(const Ray& r) { return ray_valid(r); }

namespace detail {
inline const float* node_floats(const BinaryNode& n) { return &n.min.x; }
}  // namespace detail

// kAnyHit: return at the first hit in (tnear, tfar] (occlusion); `hit` is then
// only meaningful as "something was hit". Otherwise `hit` gets the closest hit
// (t, u, v, geomID, primID in input order) and the result says whether any was
// found. The ray must be valid (ray_is_valid). Given `answer`, a
// closest-hit traversal copies its answer there, with the hit's leaf-order
// index, instead of storing it in `hit`: the caller stores it
// (ClosestHit::store) when it wants, e.g. after tracing more rays, so that
// the loads of several rays' hit ids overlap. `answer` is left untouched
// when the ray misses the root box.
template <typename Test, bool kAnyHit, bool kStats = false>
bool traverse(const Bvh2& bvh, const Ray& ray, Hit& hit, TraversalStats* stats = nullptr,
              ClosestHit* answer = nullptr) {
  if (bvh.empty()) return false;
  const BinaryNode* nodes = bvh.nodes.data();
  const LeafTriangles& tris = bvh.triangles;
  const SlabRay slab(ray);
#if defined(__AVX2__)
  const SlabRayPair pair(slab);
#endif
  const typename Test::Prepared prep = Test::prepare(ray, bvh.bounds());
  const float tnear = ray.tnear;
  float tfar = ray.tfar;
  ClosestHit closest;

  float entry = 0.0f;
  if (!slab_robust(slab, detail::node_floats(nodes[0]), tnear, tfar, entry)) return false;

  TraversalStack<2> stack;
  uint32_t current = 0;
  for (;;) {
    const BinaryNode* node = &nodes[current];
    while (!node->is_leaf()) {
      if constexpr (kStats) ++stats->nodes;
      const uint32_t li = node->index;
      const BinaryNode* left = &nodes[li];
      // Both children's child pairs (one 64-byte line each) are requested
      // now, while this pair is tested: the visited one is needed next, the
      // pushed one when it is popped (random rays miss the cache per level).
      if (!left[0].is_leaf()) __builtin_prefetch(&nodes[left[0].index]);
      if (!left[1].is_leaf()) __builtin_prefetch(&nodes[left[1].index]);
      float tl = 0.0f, tr = 0.0f;
#if defined(__AVX2__)
      const int mask = slab_robust_pair(pair, detail::node_floats(left[0]),
                                        detail::node_floats(left[1]), tnear, tfar, tl, tr);
      const bool hl = mask & 1, hr = mask & 2;
#else
      const bool hl = slab_robust(slab, detail::node_floats(left[0]), tnear, tfar, tl);
      const bool hr = slab_robust(slab, detail::node_floats(left[1]), tnear, tfar, tr);
#endif
      // A hit leaf's triangles are requested now, so their lines are on the
      // way while the other child (or the stack) is dealt with.
      if (hl && left[0].is_leaf())
        Test::prefetch(tris, LeafRange::whole(left[0].index, left[0].count));
      if (hr && left[1].is_leaf())
        Test::prefetch(tris, LeafRange::whole(left[1].index, left[1].count));
      if (hl && hr) {
        if (tr < tl) {
          stack.push(li, tl);
          node = left + 1;
        } else {
          stack.push(li + 1, tr);
          node = left;
        }
      } else if (hl) {
        node = left;
      } else if (hr) {
        node = left + 1;
      } else {
        node = nullptr;
        break;
      }
    }
    if (node &&
        intersect_leaf<Test, kAnyHit, kStats>(
            prep, tris, LeafRange::whole(node->index, node->count), tnear, tfar, closest, stats)) {
      closest.store(tris, hit);
      return true;
    }
    // Pop the next node that may still hold a closer hit.
    for (;;) {
      if (stack.empty()) {
        if (answer)
          *answer = closest;
        else if (closest.found)
          closest.store(tris, hit);
        return closest.found;
      }
      const StackEntry e = stack.pop();
      if (e.entry <= tfar) {
        current = e.node;
        break;
      }
    }
  }
}

}  // namespace hprt
