// The point queries through a layout of the bvh (core/point_query.h):
//  - locate_point: on a triangle exactly (every leaf whose closed box holds
//    the point), else the parity of the crossings of a ray from the point in
//    kInsideDirection. The watertight test decides which triangles the ray
//    crosses (exactly, with its fill rule); the side of each one's plane the
//    point lies on decides exactly whether the crossing is ahead (t > 0).
//  - closest_point: nearest first, children in order of their boxes'
//    distance, a subtree skipped once its box is farther than the best so
//    far (with a margin of 2^-40 for the boxes' rounding, so that triangles
//    at exactly the best distance are still seen for the tie rule).
// Both read the triangles' exact vertices: the watertight test's arrays.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "bvh/builders/build_tree.h"
#include "bvh/intersect/ray_triangle.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/traverse_all.h"
#include "core/exact_predicates.h"
#include "core/point_query.h"
#include "core/ray.h"

namespace hprt {

namespace detail {
inline bool box_holds(const Vec3f& lo, const Vec3f& hi, const Vec3f& p) {
  return lo.x <= p.x && p.x <= hi.x && lo.y <= p.y && p.y <= hi.y && lo.z <= p.z && p.z <= hi.z;
}

// Squared distance from p to the box, in double (+inf for an empty slot).
inline double box_distance2(float lox, float hix, float loy, float hiy, float loz, float hiz,
                            const Vec3f& p) {
  const auto axis = [](float lo, float hi, float x) {
    const double d = std::max({double(lo) - x, double(x) - hi, 0.0});
    return d * d;
  };
  return axis(lox, hix, p.x) + axis(loy, hiy, p.y) + axis(loz, hiz, p.z);
}

inline double prune_limit(double best_d2) { return best_d2 * (1.0 + 0x1p-40); }

#if defined(__AVX512F__)
// box_distance2 of the eight children of an 8-wide node (bounds as in
// WideNode) into d2; the mask of those within `limit` (empty slots, at +inf,
// never are).
inline __mmask8 near_children8(const float (&bounds)[6][8], const Vec3f& p, double limit,
                               double* d2) {
  const __m512d zero = _mm512_setzero_pd();
  const auto axis = [&](int a, float x) {
    const __m512d px = _mm512_set1_pd(x);
    const __m512d lo = _mm512_maskz_cvtps_pd(0xFF, _mm256_loadu_ps(bounds[2 * a]));
    const __m512d hi = _mm512_maskz_cvtps_pd(0xFF, _mm256_loadu_ps(bounds[2 * a + 1]));
    // The mask forms: g++ 12 reports the plain ones' undefined pass-through
    // operand as maybe-uninitialized (as in simd16.h).
    const __m512d a_lo = _mm512_sub_pd(lo, px), a_hi = _mm512_sub_pd(px, hi);
    const __m512d d =
        _mm512_mask_max_pd(zero, 0xFF, _mm512_mask_max_pd(zero, 0xFF, a_lo, a_hi), zero);
    return _mm512_mul_pd(d, d);
  };
  const __m512d sum = _mm512_add_pd(_mm512_add_pd(axis(0, p.x), axis(1, p.y)), axis(2, p.z));
  _mm512_storeu_pd(d2, sum);
  return _mm512_cmp_pd_mask(sum, _mm512_set1_pd(limit), _CMP_LE_OQ) &
         _mm512_cmp_pd_mask(sum, _mm512_set1_pd(std::numeric_limits<double>::infinity()),
                            _CMP_LT_OQ);
}
#endif

// The children of a wide node whose closed boxes hold p (empty slots never do).
template <int N>
unsigned children_holding(const WideNode<N>& node, const Vec3f& p) {
#if defined(__AVX512F__) && defined(__AVX512VL__)
  if constexpr (N == 8) {
    __mmask8 in = 0xFF;
    for (int k = 0; k < 3; ++k) {
      const __m256 x = _mm256_set1_ps(p[k]);
      in = _mm256_mask_cmp_ps_mask(in, _mm256_loadu_ps(node.bounds[2 * k]), x, _CMP_LE_OQ);
      in = _mm256_mask_cmp_ps_mask(in, x, _mm256_loadu_ps(node.bounds[2 * k + 1]), _CMP_LE_OQ);
    }
    return in;
  }
#endif
  unsigned m = 0;
  for (int i = 0; i < N; ++i)
    m |=
        unsigned(node.bounds[0][i] <= p.x && p.x <= node.bounds[1][i] && node.bounds[2][i] <= p.y &&
                 p.y <= node.bounds[3][i] && node.bounds[4][i] <= p.z && p.z <= node.bounds[5][i])
        << i;
  return m;
}

// Calls leaf(range) for every leaf whose closed box holds p; stops when it
// returns true.
template <typename Leaf>
bool any_leaf_holding(const Bvh2& bvh, const Vec3f& p, Leaf&& leaf) {
  if (bvh.empty() || !box_holds(bvh.nodes[0].min, bvh.nodes[0].max, p)) return false;
  uint32_t stack[kMaxBuildDepth + 2];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const BinaryNode& node = bvh.nodes[stack[--sp]];
    if (node.is_leaf()) {
      if (leaf(LeafRange::whole(node.index, node.count))) return true;
      continue;
    }
    for (uint32_t c = node.index; c < node.index + 2; ++c)
      if (box_holds(bvh.nodes[c].min, bvh.nodes[c].max, p)) stack[sp++] = c;
  }
  return false;
}
template <int N, typename Leaf>
bool any_leaf_holding(const WideBvh<N>& bvh, const Vec3f& p, Leaf&& leaf) {
  if (bvh.empty() || !box_holds(bvh.bounds.min, bvh.bounds.max, p)) return false;
  uint64_t stack[1 + (N - 1) * kMaxBuildDepth + N];
  int sp = 0;
  stack[sp++] = bvh.root.bits;
  while (sp > 0) {
    const NodeRef cur{stack[--sp]};
    if (cur.is_leaf()) {
      if (leaf(cur.leaf_range())) return true;
      continue;
    }
    for (unsigned m = children_holding(bvh.nodes[cur.index()], p); m; m &= m - 1)
      stack[sp++] = bvh.nodes[cur.index()].child[__builtin_ctz(m)].bits;
  }
  return false;
}

// The best candidate so far of closest_point.
struct ClosestSoFar {
  double d2;
  uint32_t geom_id = kInvalidId, prim_id = kInvalidId;
  TrianglePoint at{};
};

inline void closest_in_leaf(const LeafTriangles& tris, const LeafRange& leaf, const Vec3f& p,
                            ClosestSoFar& best) {
  for (uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i) {
    const TriangleVerts t = tris.triangle(leaf, i);
    const TrianglePoint q = closest_point_on_triangle(p, t.v0, t.v1, t.v2);
    const PrimRef& ref = tris.refs[i];
    if (closest_before(q.d2, ref.geom_id, ref.prim_id, best.d2, best.geom_id, best.prim_id)) {
      best.d2 = q.d2;
      best.geom_id = ref.geom_id;
      best.prim_id = ref.prim_id;
      best.at = q;
    }
  }
}

// Whether p lies exactly on a triangle of the leaf. With AVX-512 the
// triangles' own boxes are tested 8 at a time first (on_triangle's first
// test, the same comparisons), so the exact test runs only where p is in one.
inline bool leaf_holds_point(const LeafTriangles& tris, const LeafRange& leaf, const Vec3f& p) {
  const uint32_t end = leaf.first + leaf.count;
#if defined(__AVX512F__) && defined(__AVX512VL__)
  const float* rows = tris.vert_row(leaf.block_first, leaf.block_count, 0);
  const size_t s = leaf.block_count;  // row stride
  for (uint32_t base = leaf.first; base < end; base += 8) {
    const __mmask8 lanes = __mmask8((1u << std::min(8u, end - base)) - 1u);
    const float* r = rows + (base - leaf.block_first);
    __mmask8 in = lanes;
    for (int k = 0; k < 3; ++k) {
      const __m256 a = _mm256_maskz_loadu_ps(lanes, r + k * s);
      const __m256 b = _mm256_maskz_loadu_ps(lanes, r + (3 + k) * s);
      const __m256 c = _mm256_maskz_loadu_ps(lanes, r + (6 + k) * s);
      const __m256 x = _mm256_set1_ps(p[k]);
      in = _mm256_mask_cmp_ps_mask(in, _mm256_min_ps(a, _mm256_min_ps(b, c)), x, _CMP_LE_OQ);
      in = _mm256_mask_cmp_ps_mask(in, x, _mm256_max_ps(a, _mm256_max_ps(b, c)), _CMP_LE_OQ);
    }
    for (unsigned m = in; m; m &= m - 1) {
      const TriangleVerts t = tris.triangle(leaf, base + uint32_t(__builtin_ctz(m)));
      if (exact::on_triangle(t.v0, t.v1, t.v2, p)) return true;
    }
  }
  return false;
#else
  for (uint32_t i = leaf.first; i < end; ++i) {
    const TriangleVerts t = tris.triangle(leaf, i);
    if (exact::on_triangle(t.v0, t.v1, t.v2, p)) return true;
  }
  return false;
#endif
}

}  // namespace detail

// Whether p lies exactly on a triangle of the tree.
template <typename Bvh>
bool point_on_surface(const Bvh& bvh, const Vec3f& p) {
  return detail::any_leaf_holding(bvh, p, [&](const LeafRange& leaf) {
    return detail::leaf_holds_point(bvh.triangles, leaf, p);
  });
}

namespace detail {
// The ray whose crossings decide whether p is inside: from p along
// kInsideDirection. Boxes are entered from t = 0 on; every triangle the line
// crosses in them is taken (the leaves' lower end is -inf), and
// crosses_ahead() decides exactly whether the crossing has t > 0.
inline Ray inside_ray(const Vec3f& p) {
  Ray ray;
  ray.org = p;
  ray.dir = kInsideDirection;
  ray.tnear = 0.0f;
  ray.tfar = std::numeric_limits<float>::infinity();
  return ray;
}
inline constexpr float kInsideLeafTnear = -std::numeric_limits<float>::infinity();

// Whether the line of inside_ray(p), which hits triangle i of `leaf`,
// crosses it ahead of p: t = n.(v0 - p) / n.d > 0, decided by the side of
// the plane p lies on. (Side 0 would put p on the triangle, which
// point_on_surface rules out first.)
inline bool crosses_ahead(const LeafTriangles& tris, const LeafRange& leaf, uint32_t i,
                          const Vec3f& p) {
  const TriangleVerts t = tris.triangle(leaf, i);
  const int side = exact::orient3d(t.v0, t.v1, t.v2, p);
  const int facing = exact::plane_direction(t.v0, t.v1, t.v2, kInsideDirection);
  return side != 0 && facing != 0 && side != facing;
}
}  // namespace detail

// Inside, outside or on the surface (core/point_query.h). p must be a valid
// ray origin (finite, within Embree's FLT_LARGE).
template <typename Bvh>
PointLocation locate_point(const Bvh& bvh, const Vec3f& p) {
  if (point_on_surface(bvh, p)) return PointLocation::kOnSurface;
  unsigned crossings = 0;
  traverse_all<WatertightTest>(
      bvh, detail::inside_ray(p),
      [&](const LeafRange& leaf, uint32_t i, const TriangleHit&) {
        crossings += detail::crosses_ahead(bvh.triangles, leaf, i, p);
      },
      detail::kInsideLeafTnear);
  return crossings % 2 ? PointLocation::kInside : PointLocation::kOutside;
}

// locate_point of a wide tree in one traversal instead of two: the ray's
// (traverse_all's loop), whose stack entries also say whether the node's
// closed box holds p. The triangles of the leaves that do are checked for p
// on them, as point_on_surface checks them; every such leaf is reached, as a
// node that holds p is pushed whether or not the ray's slab test enters it
// (it does, at t = 0; a leaf entered for holding p alone adds no crossing
// ahead of p, as a crossing ahead lies in the ray's path through its box).
template <int N>
PointLocation locate_point(const WideBvh<N>& bvh, const Vec3f& p) {
  if (bvh.empty()) return PointLocation::kOutside;
  const Ray ray = detail::inside_ray(p);
  const WideSlabRay slab(ray);
  const WatertightTest::Prepared prep = WatertightTest::prepare(ray, bvh.bounds);
  struct Entry {
    uint64_t bits;
    bool holds;  // the node's closed box holds p
  };
  Entry stack[1 + (N - 1) * kMaxBuildDepth + N];
  int sp = 0;
  stack[sp++] = {bvh.root.bits, detail::box_holds(bvh.bounds.min, bvh.bounds.max, p)};
  unsigned crossings = 0;
  const auto count = [&](const LeafRange& leaf, uint32_t i, const TriangleHit&) {
    crossings += detail::crosses_ahead(bvh.triangles, leaf, i, p);
  };
  while (sp > 0) {
    const Entry e = stack[--sp];
    const NodeRef cur{e.bits};
    if (cur.is_leaf()) {
      const LeafRange leaf = cur.leaf_range();
      if (e.holds && detail::leaf_holds_point(bvh.triangles, leaf, p))
        return PointLocation::kOnSurface;
      detail::visit_leaf_hits<WatertightTest>(prep, bvh.triangles, leaf, detail::kInsideLeafTnear,
                                              ray.tfar, count);
      continue;
    }
    const WideNode<N>& node = bvh.nodes[cur.index()];
    alignas(32) float dist[N];
    const unsigned holds = e.holds ? detail::children_holding(node, p) : 0u;
    for (unsigned m = slab_wide<N>(slab, node, ray.tnear, ray.tfar, dist) | holds; m; m &= m - 1) {
      const int i = __builtin_ctz(m);
      const NodeRef c = node.child[i];
      if (c.is_leaf())
        WatertightTest::prefetch(bvh.triangles, c.leaf_range());
      else
        detail::prefetch_node(&bvh.nodes[c.index()]);
      stack[sp++] = {c.bits, ((holds >> i) & 1u) != 0};
    }
  }
  return crossings % 2 ? PointLocation::kInside : PointLocation::kOutside;
}

// The nearest point of the tree's triangles within sqrt(max_d2) of p
// (inclusive), or a ClosestPoint that is not found().
template <typename Bvh>
ClosestPoint closest_point(const Bvh& bvh, const Vec3f& p, double max_d2) {
  detail::ClosestSoFar best{max_d2};
  if (bvh.empty()) return {};
  if constexpr (std::is_same_v<Bvh, Bvh2>) {
    struct Entry {
      uint32_t node;
      double d2;
    };
    Entry stack[kMaxBuildDepth + 2];
    int sp = 0;
    const BinaryNode* nodes = bvh.nodes.data();
    const auto dist = [&](uint32_t n) {
      return detail::box_distance2(nodes[n].min.x, nodes[n].max.x, nodes[n].min.y, nodes[n].max.y,
                                   nodes[n].min.z, nodes[n].max.z, p);
    };
    stack[sp++] = {0, dist(0)};
    while (sp > 0) {
      const Entry e = stack[--sp];
      if (e.d2 > detail::prune_limit(best.d2)) continue;
      const BinaryNode& node = nodes[e.node];
      if (node.is_leaf()) {
        detail::closest_in_leaf(bvh.triangles, LeafRange::whole(node.index, node.count), p, best);
        continue;
      }
      Entry a{node.index, dist(node.index)}, b{node.index + 1, dist(node.index + 1)};
      if (a.d2 < b.d2) std::swap(a, b);  // the nearer on top
      stack[sp++] = a;
      stack[sp++] = b;
    }
  } else {
    constexpr int N = std::remove_cvref_t<decltype(bvh.nodes[0])>::kWidth;
    struct Entry {
      uint64_t ref;
      double d2;
    };
    Entry stack[1 + (N - 1) * kMaxBuildDepth + N];
    int sp = 0;
    const AABB& root = bvh.bounds;
    stack[sp++] = {bvh.root.bits, detail::box_distance2(root.min.x, root.max.x, root.min.y,
                                                        root.max.y, root.min.z, root.max.z, p)};
    while (sp > 0) {
      const Entry e = stack[--sp];
      if (e.d2 > detail::prune_limit(best.d2)) continue;
      const NodeRef cur{e.ref};
      if (cur.is_leaf()) {
        detail::closest_in_leaf(bvh.triangles, cur.leaf_range(), p, best);
        continue;
      }
      const WideNode<N>& node = bvh.nodes[cur.index()];
      Entry near[N];
      int n = 0;
      const double limit = detail::prune_limit(best.d2);
#if defined(__AVX512F__)
      if constexpr (N == 8) {
        // The eight box distances at once, the same double arithmetic.
        double d2s[8];
        uint64_t refs[8];
        const __mmask8 keep = detail::near_children8(node.bounds, p, limit, d2s);
        n = __builtin_popcount(keep);
        _mm512_mask_compressstoreu_pd(d2s, keep, _mm512_loadu_pd(d2s));
        _mm512_mask_compressstoreu_epi64(refs, keep, _mm512_loadu_si512(node.child));
        for (int j = 0; j < n; ++j) {
          int k = j;  // insertion in descending distance, as below
          while (k > 0 && near[k - 1].d2 < d2s[j]) {
            near[k] = near[k - 1];
            --k;
          }
          near[k] = {refs[j], d2s[j]};
        }
        for (int k = 0; k < n; ++k) stack[sp++] = near[k];
        continue;
      }
#endif
      for (int i = 0; i < N; ++i) {
        if (node.child[i].empty()) continue;
        const double d2 =
            detail::box_distance2(node.bounds[0][i], node.bounds[1][i], node.bounds[2][i],
                                  node.bounds[3][i], node.bounds[4][i], node.bounds[5][i], p);
        if (d2 > limit) continue;
        // Insertion in descending distance: the nearest goes on the stack last.
        int k = n++;
        while (k > 0 && near[k - 1].d2 < d2) {
          near[k] = near[k - 1];
          --k;
        }
        near[k] = {node.child[i].bits, d2};
      }
      for (int k = 0; k < n; ++k) stack[sp++] = near[k];
    }
  }
  if (best.geom_id == kInvalidId) return {};
  return to_closest_point(best.at, best.geom_id, best.prim_id);
}

}  // namespace hprt
