// Bottom-up refit of a FlatBvh: one depth-first recursion that, at a leaf,
// re-gathers its triangles (verts, edges) from the scene through their input
// refs and bounds them, and at an inner node unions its two children's boxes.
// The top levels (parallel_depth: by triangle count) run their two subtrees as oneTBB tasks
// (parallel_invoke), deeper levels sequentially. Box unions (min/max) are
// exact in any order and the SAH sums follow the fixed tree shape (left +
// right + own), so the result never depends on the thread count. The same
// recursion, without gathering, gives flat_sah_cost.
#include "bvh/refit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

namespace hprt {
namespace {

// Subtrees above depth parallel_depth() are refitted as parallel tasks: one
// level per doubling of the triangle count above kTaskTriangles (so a task
// covers ~kTaskTriangles or more in a balanced tree), at most 2^10 tasks:
// enough to balance uneven SAH trees over many threads, few enough that
// spawning stays negligible next to the gathering.
constexpr size_t kTaskTriangles = 2048;
constexpr int kMaxParallelDepth = 10;

int parallel_depth(size_t triangles) {
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

// kGather: refit (Bvh = FlatBvh), rewriting the arrays kWrite names;
// otherwise only sum the SAH (Bvh = const FlatBvh).
template <bool kGather, RefitTriangles kWrite, typename Bvh>
Partial visit(Bvh& bvh, const Scene* scene, const Vec3u* tri_index, uint32_t index, int depth,
              int parallel) {
  auto& node = bvh.nodes[index];
  Partial p;
  if (node.is_leaf()) {
    if constexpr (kGather) {
      p = refit_leaf<kWrite>(bvh.triangles, *scene, tri_index, node.index, node.count);
    } else {
      p.box = AABB(node.min, node.max);
    }
    p.area_cost = double(p.box.half_area()) * node.count;
    p.unit_cost = node.count;
  } else {
    const uint32_t left = node.index;
    Partial l, r;
    if (depth < parallel) {
      tbb::parallel_invoke(
          [&] { l = visit<kGather, kWrite>(bvh, scene, tri_index, left, depth + 1, parallel); },
          [&] {
            r = visit<kGather, kWrite>(bvh, scene, tri_index, left + 1, depth + 1, parallel);
          });
    } else {
      l = visit<kGather, kWrite>(bvh, scene, tri_index, left, depth + 1, parallel);
      r = visit<kGather, kWrite>(bvh, scene, tri_index, left + 1, depth + 1, parallel);
    }
    p.box = l.box;
    p.box.extend(r.box);
    p.valid = l.valid && r.valid;
    p.area_cost = l.area_cost + r.area_cost + double(p.box.half_area());
    p.unit_cost = l.unit_cost + r.unit_cost + 1.0;
  }
  if constexpr (kGather) {
    node.min = p.box.min;
    node.max = p.box.max;
  }
  return p;
}

double normalised(const Partial& root) {
  const double root_area = root.box.half_area();
  return root_area > 0.0 ? root.area_cost / root_area : root.unit_cost;
}

}  // namespace

RefitIndex make_refit_index(const FlatBvh& bvh, const Scene& scene) {
  RefitIndex index;
  index.triangles.resize(bvh.triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, index.triangles.size(), 16384),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t j = range.begin(); j != range.end(); ++j) {
                        const PrimRef r = bvh.triangles.refs[j];
                        index.triangles[j] = scene.meshes[r.geom_id].triangles[r.prim_id];
                      }
                    });
  return index;
}

RefitResult refit(FlatBvh& bvh, const Scene& scene, RefitTriangles triangles,
                  const RefitIndex* index) {
  RefitResult r;
  if (bvh.empty()) return r;
  const int parallel = parallel_depth(bvh.triangles.size());
  const Vec3u* tri =
      index && index->triangles.size() == bvh.triangles.size() ? index->triangles.data() : nullptr;
  Partial root;
  switch (triangles) {
    case RefitTriangles::kBoth:
      root = visit<true, RefitTriangles::kBoth>(bvh, &scene, tri, 0, 0, parallel);
      break;
    case RefitTriangles::kVerts:
      root = visit<true, RefitTriangles::kVerts>(bvh, &scene, tri, 0, 0, parallel);
      break;
    case RefitTriangles::kEdges:
      root = visit<true, RefitTriangles::kEdges>(bvh, &scene, tri, 0, 0, parallel);
      break;
  }
  r.valid = root.valid;
  r.sah_cost = normalised(root);
  return r;
}

double flat_sah_cost(const FlatBvh& bvh) {
  if (bvh.empty()) return 0.0;
  return normalised(visit<false, RefitTriangles::kBoth>(bvh, nullptr, nullptr, 0, 0,
                                                        parallel_depth(bvh.triangles.size())));
}

}  // namespace hprt
