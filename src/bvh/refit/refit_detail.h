// What the binary (refit_bvh2.cpp) and wide (refit_wide.cpp) refits share: the
// per-subtree partial result, the leaf gather, the depth above which subtrees
// run as parallel tasks, and the SAH normalisation.
#pragma once

#include <cstddef>
#include <stdexcept>

#include <immintrin.h>

#include "bvh/input/box_ref.h"
#include "bvh/layout/leaf_triangles.h"
#include "bvh/refit/refit_bvh2.h"
#include "core/aabb.h"
#include "core/scene.h"

namespace hprt::refit_detail {

// Subtrees above depth parallel_depth() are refitted as parallel tasks: one
// level per doubling of the triangle count above kTaskTriangles (so a task
// covers ~kTaskTriangles or more in a balanced tree), at most 2^10 tasks:
// enough to balance uneven SAH trees over many threads, few enough that
// spawning stays negligible next to the gathering.
constexpr size_t kTaskTriangles = 2048;
constexpr int kMaxParallelDepth = 10;

inline int parallel_depth(size_t triangles) {
  int d = 0;
  while (d < kMaxParallelDepth && (triangles >> d) >= 2 * kTaskTriangles) ++d;
  return d;
}

struct Partial {
  AABB box;
  double area_cost = 0.0;  // sum of half_area(n) * cost(n) over the subtree
  double unit_cost = 0.0;  // sum of cost(n) (the weights when the root area is 0)
  bool valid = true;
};

// (x, y, z, 0) without reading past v.
inline __m128 load3(const Vec3f& v) { return _mm_setr_ps(v.x, v.y, v.z, 0.0f); }

// nonzero_area(a, b, c) of three (x, y, z, _) vectors: the same exact
// answer (products of floats are exact in double), four lanes at once.
inline bool nonzero_area(__m128 a, __m128 b, __m128 c) {
#if defined(__AVX2__)
  const __m256d e1 = _mm256_cvtps_pd(_mm_sub_ps(b, a)), e2 = _mm256_cvtps_pd(_mm_sub_ps(c, a));
  constexpr int kYzx = _MM_SHUFFLE(3, 0, 2, 1), kZxy = _MM_SHUFFLE(3, 1, 0, 2);
  const __m256d n = _mm256_sub_pd(
      _mm256_mul_pd(_mm256_permute4x64_pd(e1, kYzx), _mm256_permute4x64_pd(e2, kZxy)),
      _mm256_mul_pd(_mm256_permute4x64_pd(e1, kZxy), _mm256_permute4x64_pd(e2, kYzx)));
  return (_mm256_movemask_pd(_mm256_cmp_pd(n, _mm256_setzero_pd(), _CMP_NEQ_UQ)) & 0x7) != 0;
#else
  alignas(16) float va[4], vb[4], vc[4];
  _mm_store_ps(va, a);
  _mm_store_ps(vb, b);
  _mm_store_ps(vc, c);
  return hprt::nonzero_area({va[0], va[1], va[2]}, {vb[0], vb[1], vb[2]}, {vc[0], vc[1], vc[2]});
#endif
}

// The vertices of leaf-order triangle j (when there is one), for the gather
// kVertexAhead triangles on: the walk visits the leaves in leaf order, so
// they are the ones it reads next, at random in the mesh. Always inlined:
// GCC deletes a call whose only effects are prefetches.
constexpr uint32_t kVertexAhead = 8;
[[gnu::always_inline]] inline void prefetch_vertices(const LeafTriangles& tris, const Scene& scene,
                                                     const Vec3u* index, uint32_t j) {
  if (j >= tris.size()) return;
  const Vec3f* positions = scene.meshes[tris.refs[j].geom_id].positions.data();
  const Vec3u t = index[j];
  for (int k = 0; k < 3; ++k)
    _mm_prefetch(reinterpret_cast<const char*>(&positions[t[k]]), _MM_HINT_T0);
}

// Gathers the leaf's triangles into leaf order and bounds them; `valid` is
// TriangleMesh::triangle_valid on the gathered vertices (finite, and
// nonzero_area: exact, so a triangle the builder kept is valid here exactly
// when prim info would keep it).
template <RefitTriangles kWrite>
inline Partial refit_leaf(LeafTriangles& tris, const Scene& scene, const Vec3u* index,
                          const LeafRange& leaf) {
  Partial p;
  VecBox box;  // min / max are exact: the same box as AABB::extend, in vector registers
  for (uint32_t j = leaf.first; j < leaf.first + leaf.count; ++j) {
    if (index) prefetch_vertices(tris, scene, index, j + kVertexAhead);
    const PrimRef ref = tris.refs[j];
    const TriangleMesh& mesh = scene.meshes[ref.geom_id];
    const Vec3u t = index ? index[j] : mesh.triangles[ref.prim_id];
    const Vec3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    const Vec3f e1 = b - a, e2 = c - a;
    const __m128 va = load3(a), vb = load3(b), vc = load3(c);
    if constexpr (kWrite != RefitTriangles::kEdges) tris.set_triangle(leaf, j, a, b, c);
    if constexpr (kWrite != RefitTriangles::kVerts) tris.edges[j] = TriangleEdges{a, e1, e2};
    // All nine coordinates finite: then 0 * each is 0 (inf and NaN give NaN).
    const __m128 zero = _mm_setzero_ps();
    const __m128 z =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(va, zero), _mm_mul_ps(vb, zero)), _mm_mul_ps(vc, zero));
    const bool finite = _mm_movemask_ps(_mm_cmpeq_ps(z, zero)) == 0xF;
    p.valid = p.valid && finite && nonzero_area(va, vb, vc);
    box.extend(_mm_min_ps(va, _mm_min_ps(vb, vc)), _mm_max_ps(va, _mm_max_ps(vb, vc)));
  }
  p.box = box.aabb();
  return p;
}

inline void check_arrays(const LeafTriangles& tris, RefitTriangles which) {
  if (!tris.holds(which))
    throw std::invalid_argument("refit: the layout does not hold the triangle arrays asked for");
}

inline double normalised(const Partial& root) {
  const double root_area = root.box.half_area();
  return root_area > 0.0 ? root.area_cost / root_area : root.unit_cost;
}

}  // namespace hprt::refit_detail
