// Every hit along each of several rays of the wide layout (the count, all
// and inside queries on large trees), several rays in flight per thread, as
// traverse_interleaved.h does for the closest and any hit: K rays take turns,
// one node or leaf each, and the children a turn pushes are requested then,
// so a popped node's lines have had the other rays' turns to arrive. Each ray
// visits the same nodes and tests the same triangles as traverse_all (only
// the order of its pops differs), so every hit it reports is the one
// traverse_all reports, and a count is the same.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>

#include "bvh/traverse/traverse_all.h"
#include "bvh/traverse/traverse_interleaved.h"

namespace hprt {

namespace detail {

template <typename Test, int N>
struct AllHitsInFlight {
  AllHitsInFlight() : slab(Ray{}) {}
  // Made in place (std::construct_at) for each ray; the stack's entries are
  // left uninitialised.
  AllHitsInFlight(const Ray& r, size_t index, NodeRef root, const AABB& bounds, float leaf_tnear)
      : slab(r),
        prep(Test::prepare(r, bounds)),
        tnear(r.tnear),
        tfar(r.tfar),
        leaf_tnear(leaf_tnear),
        ray(index) {
    stack.push(root.bits);
  }

  WideSlabRay slab;
  typename Test::Prepared prep;
  float tnear, tfar, leaf_tnear;
  size_t ray;  // index into the batch
  UnorderedStack<N> stack;
};

}  // namespace detail

// For k in [0, count) with rays[first + k] valid, calls
// visit(first + k, leaf, i, hit) for every triangle hit along that ray in
// its (tnear, tfar] (traverse_all's visits; with `leaf_tnear`, the triangle
// tests' lower end for every ray, as traverse_all's), up to kRaysInFlight
// rays at a time; invalid rays are skipped. The tree must not be empty.
template <typename Test, int N, typename Visit>
void traverse_all_interleaved(const WideBvh<N>& bvh, const Ray* rays, size_t first, size_t count,
                              Visit&& visit, std::optional<float> leaf_tnear = std::nullopt) {
  constexpr int K = detail::kRaysInFlight;
  detail::AllHitsInFlight<Test, N> slot[K];
  bool live[K] = {};
  size_t next = 0;
  const auto start = [&](detail::AllHitsInFlight<Test, N>& s) {
    for (; next < count; ++next) {
      const Ray& r = rays[first + next];
      if (!ray_is_valid(r)) continue;
      std::construct_at(&s, r, first + next, bvh.root, bvh.bounds, leaf_tnear.value_or(r.tnear));
      ++next;
      return true;
    }
    return false;
  };
  int in_flight = 0;
  for (int k = 0; k < K; ++k) in_flight += (live[k] = start(slot[k]));
  while (in_flight > 0) {
    for (int k = 0; k < K; ++k) {
      if (!live[k]) continue;
      detail::AllHitsInFlight<Test, N>& s = slot[k];
      const NodeRef cur{s.stack.pop()};
      if (cur.is_leaf()) {
        const auto hit = [&](const LeafRange& leaf, uint32_t i, const TriangleHit& h) {
          visit(s.ray, leaf, i, h);
        };
        detail::visit_leaf_hits<Test>(s.prep, bvh.triangles, cur.leaf_range(), s.leaf_tnear, s.tfar,
                                      hit);
      } else {
        const WideNode<N>& node = bvh.nodes[cur.index()];
        alignas(32) float dist[N];
        for (unsigned m = slab_wide<N>(s.slab, node, s.tnear, s.tfar, dist); m; m &= m - 1) {
          const NodeRef c = node.child[__builtin_ctz(m)];
          detail::prefetch_ref<Test>(bvh, c);
          s.stack.push(c.bits);
        }
      }
      if (s.stack.empty() && !(live[k] = start(s))) --in_flight;
    }
  }
}

}  // namespace hprt
