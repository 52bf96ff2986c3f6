// What both traversals (binary and wide) do at a leaf: test its triangles in
// order, shrinking tfar to each closer hit, and keep the closest, the
// smallest (t, leaf index); the Hit is written once, when the traversal ends.
#pragma once

#include <cstdint>

#include "bvh/leaf_triangles.h"
#include "bvh/triangle_test.h"
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

// Tests triangles [first, first + count). With kAnyHit it returns true at the
// first hit (recorded in `closest`); otherwise it always returns false.
template <typename Test, bool kAnyHit, bool kStats>
HPRT_FORCE_INLINE bool intersect_leaf(const typename Test::Prepared& prep,
                                      const LeafTriangles& tris, uint32_t first, uint32_t count,
                                      float tnear, float& tfar, ClosestHit& closest,
                                      TraversalStats* stats) {
  if constexpr (kStats) ++stats->leaves;
  const uint32_t end = first + count;
  for (uint32_t i = first; i < end; ++i) {
    if constexpr (kStats) ++stats->triangles;
    TriangleHit h;
    if (Test::intersect(prep, tris, i, tnear, tfar, h)) {
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
