// Bottom-up refit of a Bvh2: one depth-first recursion that, at a leaf,
// re-gathers its triangles (verts, edges) from the scene through their input
// refs and bounds them, and at an inner node unions its two children's boxes.
// The top levels (parallel_depth: by triangle count) run their two subtrees as oneTBB tasks
// (parallel_invoke), deeper levels sequentially. Box unions (min/max) are
// exact in any order and the SAH sums follow the fixed tree shape (left +
// right + own), so the result never depends on the thread count. The same
// recursion, without gathering, gives bvh2_sah_cost.
#include "bvh/refit/refit_bvh2.h"

#include "bvh/refit/refit_detail.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

namespace hprt {
namespace {

using refit_detail::parallel_depth;
using refit_detail::Partial;
using refit_detail::refit_leaf;

// kGather: refit (Bvh = Bvh2), rewriting the arrays kWrite names;
// otherwise only sum the SAH (Bvh = const Bvh2).
template <bool kGather, RefitTriangles kWrite, typename Bvh>
Partial visit(Bvh& bvh, const Scene* scene, const Vec3u* tri_index, uint32_t index, int depth,
              int parallel) {
  auto& node = bvh.nodes[index];
  Partial p;
  if (node.is_leaf()) {
    if constexpr (kGather) {
      p = refit_leaf<kWrite>(bvh.triangles, *scene, tri_index,
                             LeafRange::whole(node.index, node.count));
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

}  // namespace

RefitIndex make_refit_index(const Bvh2& bvh, const Scene& scene) {
  return make_refit_index(bvh.triangles, scene);
}

RefitIndex make_refit_index(const LeafTriangles& triangles, const Scene& scene) {
  RefitIndex index;
  make_refit_index(triangles, scene, index);
  return index;
}

void make_refit_index(const LeafTriangles& triangles, const Scene& scene, RefitIndex& index) {
  index.triangles.reset(triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, index.triangles.size(), 16384),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t j = range.begin(); j != range.end(); ++j) {
                        const PrimRef r = triangles.refs[j];
                        index.triangles[j] = scene.meshes[r.geom_id].triangles[r.prim_id];
                      }
                    });
}

RefitResult refit(Bvh2& bvh, const Scene& scene, RefitTriangles triangles,
                  const RefitIndex* index) {
  RefitResult r;
  if (bvh.empty()) return r;
  refit_detail::check_arrays(bvh.triangles, triangles);
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
  r.sah_cost = refit_detail::normalised(root);
  return r;
}

double bvh2_sah_cost(const Bvh2& bvh) {
  if (bvh.empty()) return 0.0;
  return refit_detail::normalised(visit<false, RefitTriangles::kBoth>(
      bvh, nullptr, nullptr, 0, 0, parallel_depth(bvh.triangles.size())));
}

}  // namespace hprt
