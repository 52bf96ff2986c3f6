// What both traversals (binary and wide) do at a leaf: test its triangles in
// order, shrinking tfar to each closer hit, and keep the closest, the
// smallest (t, leaf index); the Hit is written once, when the traversal ends.
#pragma once

#include <cstdint>
#include <type_traits>

#include "bvh/intersect/ray_triangle.h"
#include "bvh/intersect/ray_triangle_lanes.h"
#include "bvh/layout/leaf_triangles.h"
#include "core/force_inline.h"
#include "core/hit.h"

namespace hprt {

struct TraversalStats {
  uint64_t nodes = 0;      // inner nodes whose children were tested
  uint64_t leaves = 0;     // leaves visited
  uint64_t triangles = 0;  // ray/triangle tests
};

struct ClosestHit {
  bool found = false;
  uint32_t index = 0;  // leaf-order triangle
  TriangleHit best{};

  // A hit at the closest t so far (a shared edge or vertex) wins only with a
  // lower leaf index, so the answer does not depend on the order in which
  // leaves were visited (single rays and packets agree).
  HPRT_FORCE_INLINE bool loses_tie(uint32_t i, float t) const {
    return found && t == best.t && i > index;
  }

  HPRT_FORCE_INLINE void store(const LeafTriangles& tris, Hit& hit) const {
    hit.t = best.t;
    hit.u = best.u;
    hit.v = best.v;
    hit.geom_id = tris.refs[index].geom_id;
    hit.prim_id = tris.refs[index].prim_id;
  }
};

#if defined(__AVX512F__) && defined(__AVX512VL__)
#define HPRT_HAS_LEAF_LANES 1
// intersect_leaf for the watertight test, up to 8 triangles at a time (one
// lane each; chunks of up to 4 on 4 lanes, whose shorter latency a single
// ray's traversal waits less on than 8 lanes'). Each chunk's lanes are tested against
// the same tfar, so the hit kept is the one the triangle-by-triangle loop
// would end with: the smallest t, the lowest index among equal t (then
// loses_tie against earlier leaves).
template <bool kAnyHit>
HPRT_FORCE_INLINE bool intersect_leaf_lanes(const WatertightTest::Prepared& prep,
                                            const LeafTriangles& tris, const LeafRange& leaf,
                                            float tnear, float& tfar, ClosestHit& closest) {
  const uint32_t end = leaf.first + leaf.count;
  for (uint32_t base = leaf.first; base < end; base += 8) {
    alignas(32) float t[8], u[8], v[8];
    const uint32_t n = end - base < 8 ? end - base : 8;
    const unsigned hit = n <= 4
                             ? watertight_leaf<4>(prep, tris, leaf, base, n, tnear, tfar, t, u, v)
                             : watertight_leaf<8>(prep, tris, leaf, base, n, tnear, tfar, t, u, v);
    if (!hit) continue;
    int best = __builtin_ctz(hit);
    if constexpr (!kAnyHit)
      for (unsigned m = hit & (hit - 1); m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (t[l] < t[best]) best = l;
      }
    const uint32_t i = base + uint32_t(best);
    if constexpr (!kAnyHit)
      if (closest.loses_tie(i, t[best])) continue;
    if (!closest.found) __builtin_prefetch(&tris.refs[i]);
    closest.found = true;
    closest.index = i;
    closest.best = TriangleHit{t[best], u[best], v[best]};
    if constexpr (kAnyHit) return true;
    tfar = t[best];
  }
  return false;
}
#endif

// Tests the leaf's triangles. With kAnyHit it returns true at the first hit
// (recorded in `closest`); otherwise it always returns false. Leaves of two
// or more triangles go through the lane test where it is built (the same
// hits); counting tests (kStats) keeps the loop.
template <typename Test, bool kAnyHit, bool kStats>
HPRT_FORCE_INLINE bool intersect_leaf(const typename Test::Prepared& prep,
                                      const LeafTriangles& tris, const LeafRange& leaf, float tnear,
                                      float& tfar, ClosestHit& closest, TraversalStats* stats) {
#if defined(HPRT_HAS_LEAF_LANES)
  if constexpr (std::is_same_v<Test, WatertightTest> && !kStats)
    if (leaf.count >= 2)
      return intersect_leaf_lanes<kAnyHit>(prep, tris, leaf, tnear, tfar, closest);
#endif
  if constexpr (kStats) ++stats->leaves;
  const uint32_t end = leaf.first + leaf.count;
  for (uint32_t i = leaf.first; i < end; ++i) {
    if constexpr (kStats) ++stats->triangles;
    TriangleHit h;
    if (Test::intersect(prep, tris, leaf, i, tnear, tfar, h)) {
      if constexpr (!kAnyHit)
        if (closest.loses_tie(i, h.t)) continue;
      if (!closest.found) __builtin_prefetch(&tris.refs[i]);  // read once, at the end
      closest.found = true;
      closest.index = i;
      closest.best = h;
      if constexpr (kAnyHit) return true;
      tfar = h.t;
    }
  }
  return false;
}

}  // namespace hprt
