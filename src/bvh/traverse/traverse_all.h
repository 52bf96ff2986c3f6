// Every hit along a ray (the count and all queries): the traversal visits
// every node whose box the ray's interval (tnear, tfar] enters, tfar never
// shrinks, and every triangle of every such leaf is tested; `visit(i, hit)`
// is called once per triangle hit (i = leaf-order index). Each crossing of a
// surface is one hit: the watertight test decides edges and vertices by its
// fill rule (ray_triangle_exact.h). No order: the caller sorts if it needs.
// `leaf_tnear` (default: the ray's tnear) is the triangle tests' lower end
// alone: the inside query visits boxes from t = 0 but takes every triangle
// hit there, deciding the sign of t exactly itself.
#pragma once

#include <cstdint>
#include <type_traits>

#include "bvh/builders/build_tree.h"
#include "bvh/intersect/leaf_intersect.h"
#include "bvh/intersect/ray_box.h"
#include "bvh/intersect/ray_box_wide.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/traverse_wide.h"
#include "bvh/traverse/unordered_stack.h"
#include "core/ray.h"

namespace hprt {

namespace detail {
// The watertight test goes through its leaf lanes where they are built
// (the same hits, ray_triangle_lanes.h).
template <typename Test, typename Visit>
HPRT_FORCE_INLINE void visit_leaf_hits(const typename Test::Prepared& prep,
                                       const LeafTriangles& tris, const LeafRange& leaf,
                                       float tnear, float tfar, Visit& visit) {
#if defined(HPRT_HAS_LEAF_LANES)
  if constexpr (std::is_same_v<Test, WatertightTest>) {
    const uint32_t end = leaf.first + leaf.count;
    for (uint32_t base = leaf.first; base < end; base += 8) {
      alignas(32) float t[8], u[8], v[8];
      const uint32_t n = end - base < 8 ? end - base : 8;
      const unsigned hit =
          n <= 4 ? watertight_leaf<4>(prep, tris, leaf, base, n, tnear, tfar, t, u, v)
                 : watertight_leaf<8>(prep, tris, leaf, base, n, tnear, tfar, t, u, v);
      for (unsigned m = hit; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        visit(leaf, base + uint32_t(l), TriangleHit{t[l], u[l], v[l]});
      }
    }
    return;
  }
#endif
  for (uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i) {
    TriangleHit h;
    if (Test::intersect(prep, tris, leaf, i, tnear, tfar, h)) visit(leaf, i, h);
  }
}
}  // namespace detail

// The ray must be valid (ray_valid). visit(leaf, i, hit): triangle i of the
// leaf range `leaf` (LeafTriangles::triangle reads its vertices).
template <typename Test, typename Visit>
void traverse_all(const Bvh2& bvh, const Ray& ray, Visit&& visit, float leaf_tnear) {
  if (bvh.empty()) return;
  const BinaryNode* nodes = bvh.nodes.data();
  const SlabRay slab(ray);
  const typename Test::Prepared prep = Test::prepare(ray, bvh.bounds());
  float entry = 0.0f;
  if (!slab_robust(slab, &nodes[0].min.x, ray.tnear, ray.tfar, entry)) return;
  uint32_t stack[kMaxBuildDepth + 2];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const BinaryNode& node = nodes[stack[--sp]];
    if (node.is_leaf()) {
      detail::visit_leaf_hits<Test>(prep, bvh.triangles, LeafRange::whole(node.index, node.count),
                                    leaf_tnear, ray.tfar, visit);
      continue;
    }
    for (uint32_t c = node.index; c < node.index + 2; ++c)
      if (slab_robust(slab, &nodes[c].min.x, ray.tnear, ray.tfar, entry)) stack[sp++] = c;
  }
}

template <typename Test, int N, typename Visit>
void traverse_all(const WideBvh<N>& bvh, const Ray& ray, Visit&& visit, float leaf_tnear) {
  if (bvh.empty()) return;
  const WideSlabRay slab(ray);
  const typename Test::Prepared prep = Test::prepare(ray, bvh.bounds);
  detail::UnorderedStack<N> stack;  // no order needed: unordered_stack.h
  stack.push(bvh.root.bits);
  while (!stack.empty()) {
    const uint64_t bits = stack.pop();
    const NodeRef cur{bits};
    if (cur.is_leaf()) {
      detail::visit_leaf_hits<Test>(prep, bvh.triangles, cur.leaf_range(), leaf_tnear, ray.tfar,
                                    visit);
      continue;
    }
    const WideNode<N>& node = bvh.nodes[cur.index()];
    alignas(32) float dist[N];
    for (unsigned m = slab_wide<N>(slab, node, ray.tnear, ray.tfar, dist); m; m &= m - 1) {
      const NodeRef c = node.child[__builtin_ctz(m)];
      // Requested now, used when popped (random rays miss the cache per level).
      if (c.is_leaf())
        Test::prefetch(bvh.triangles, c.leaf_range());
      else
        detail::prefetch_node(&bvh.nodes[c.index()]);
      stack.push(c.bits);
    }
  }
}

template <typename Test, typename Bvh, typename Visit>
void traverse_all(const Bvh& bvh, const Ray& ray, Visit&& visit) {
  traverse_all<Test>(bvh, ray, visit, ray.tnear);
}

}  // namespace hprt
