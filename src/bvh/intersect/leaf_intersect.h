// What both traversals (binary and wide) do at a leaf: test its triangles in
// order, shrinking tfar to each closer hit, and keep the closest, the
// smallest (t, leaf index); the Hit is written once, when the traversal ends.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "bvh/intersect/ray_triangle.h"
#include "bvh/intersect/ray_triangle_lanes.h"
#include "bvh/layout/leaf_triangles.h"
#include "core/force_inline.h"
#include "core/hit.h"
#include "core/hit_columns.h"
#include "core/triangle_normal.h"

namespace hprt {

struct TraversalStats {
  uint64_t nodes = 0;      // inner nodes whose children were tested
  uint64_t leaves = 0;     // leaves visited
  uint64_t triangles = 0;  // ray/triangle tests
};

struct ClosestHit {
  bool found = false;
  uint32_t index = 0;                         // leaf-order triangle
  uint32_t block_first = 0, block_count = 0;  // its verts block (LeafRange)
  TriangleHit best{};

  HPRT_FORCE_INLINE void keep(uint32_t i, const LeafRange& leaf, const TriangleHit& h) {
    found = true;
    index = i;
    block_first = leaf.block_first;
    block_count = leaf.block_count;
    best = h;
  }

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

// A closest-hit batch's answers written as columns (core/hit_columns.h)
// instead of Hit records, when the traversal ends each ray. The normal is
// the unit normal (core/triangle_normal.h) of the exact vertices the
// watertight test read, whose lines are still in the caches then; or, for
// trees without them (the Möller–Trumbore test's edges do not reproduce the
// vertices), copied from `table`, the normals in leaf order.
struct HitColumnWriter {
  HitColumns out;
  const LeafTriangles* tris = nullptr;
  const float* table = nullptr;

  HPRT_FORCE_INLINE void prefetch(const ClosestHit& closest) const {
    if (table) __builtin_prefetch(table + 3 * size_t(closest.index));
  }
  HPRT_FORCE_INLINE void write(const ClosestHit& closest, size_t ray) const {
    if (!closest.found) {
      out.write_miss(ray);
      return;
    }
    Hit h;
    closest.store(*tris, h);
    float n[3] = {0.0f, 0.0f, 0.0f};
    if (out.normal) {
      if (table) {
        const float* src = table + 3 * size_t(closest.index);
        n[0] = src[0], n[1] = src[1], n[2] = src[2];
      } else {
        const TriangleVerts v = tris->triangle(
            LeafRange{0, 0, closest.block_first, closest.block_count}, closest.index);
        unit_normal(&v.v0.x, &v.v1.x, &v.v2.x, n);
      }
    }
    out.write(ray, h, n);
  }
  // The same batch with its rays from `first` on: a packet's (traverse_packet.h).
  HitColumnWriter from(size_t first) const { return {out.from(first), tris, table}; }

#if defined(__AVX512F__)
  // write() for rays 0..16, a packet's answers (traverse_packet.h): every
  // column's 16 entries set to a miss's with one vector store each, then the
  // lanes that hit written over them: misses, most lanes of a camera
  // packet, then cost no scalar stores and per-column checks.
  HPRT_FORCE_INLINE void write_packet(const ClosestHit* closest) const {
    unsigned found = 0;
    for (int l = 0; l < 16; ++l) found |= unsigned(closest[l].found) << l;
    const __m512 zero = _mm512_setzero_ps();
    if (out.t) _mm512_storeu_ps(out.t, _mm512_set1_ps(std::numeric_limits<float>::infinity()));
    const __m512i none = _mm512_set1_epi32(int(kInvalidId));
    if (out.geom_id) _mm512_storeu_si512(out.geom_id, none);
    if (out.prim_id) _mm512_storeu_si512(out.prim_id, none);
    if (out.uv)
      for (int k = 0; k < 2; ++k) _mm512_storeu_ps(out.uv + 16 * k, zero);
    if (out.normal)
      for (int k = 0; k < 3; ++k) _mm512_storeu_ps(out.normal + 16 * k, zero);
    for (unsigned m = found; m; m &= m - 1) {
      const int l = __builtin_ctz(m);
      write(closest[l], size_t(l));
    }
  }
#endif
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
    closest.keep(i, leaf, TriangleHit{t[best], u[best], v[best]});
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
      closest.keep(i, leaf, h);
      if constexpr (kAnyHit) return true;
      tfar = h.t;
    }
  }
  return false;
}

}  // namespace hprt
