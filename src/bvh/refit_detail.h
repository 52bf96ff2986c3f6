// What the binary (refit.cpp) and wide (refit_wide.cpp) refits share: the
// per-subtree partial result, the leaf gather, the depth above which subtrees
// run as parallel tasks, and the SAH normalisation.
#pragma once

#include <cstddef>

#include "bvh/leaf_triangles.h"
#include "bvh/refit.h"
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

// Gathers the leaf's triangles into leaf order and bounds them; `valid` is
// TriangleMesh::triangle_valid on the gathered vertices (same expression, so
// a triangle the builder kept is valid here exactly when prim info would keep it).
template <RefitTriangles kWrite>
inline Partial refit_leaf(LeafTriangles& tris, const Scene& scene, const Vec3u* index,
                          uint32_t first, uint32_t count) {
  Partial p;
  for (uint32_t j = first; j < first + count; ++j) {
    const PrimRef ref = tris.refs[j];
    const TriangleMesh& mesh = scene.meshes[ref.geom_id];
    const Vec3u t = index ? index[j] : mesh.triangles[ref.prim_id];
    const Vec3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    const Vec3f e1 = b - a, e2 = c - a;
    if constexpr (kWrite != RefitTriangles::kEdges) tris.verts[j] = TriangleVerts{a, b, c};
    if constexpr (kWrite != RefitTriangles::kVerts) tris.edges[j] = TriangleEdges{a, e1, e2};
    const Vec3f n = cross(e1, e2);
    p.valid = p.valid && is_finite(a) && is_finite(b) && is_finite(c) &&
              (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f);
    p.box.extend(a);
    p.box.extend(b);
    p.box.extend(c);
  }
  return p;
}

inline double normalised(const Partial& root) {
  const double root_area = root.box.half_area();
  return root_area > 0.0 ? root.area_cost / root_area : root.unit_cost;
}

}  // namespace hprt::refit_detail
