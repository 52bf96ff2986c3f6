// One depth-first recursion over wide nodes, as refit_bvh2.cpp's over binary ones:
// each slot's box comes from its leaf's gathered triangles or its child
// node's slots; the node adds its own box and its collapsed binary nodes'
// (unions of slot ranges) to the SAH sums, in slot order, so the result never
// depends on the thread count. The top levels run their children as oneTBB
// tasks.
#include "bvh/refit/refit_wide.h"

#include <tbb/parallel_for.h>

#include "bvh/refit/refit_detail.h"

namespace hprt {
namespace {

using refit_detail::Partial;

// kGather: refit (Bvh = WideBvh<N>), rewriting the arrays kWrite names;
// otherwise only sum the SAH (Bvh = const WideBvh<N>).
template <bool kGather, RefitTriangles kWrite, int N, typename Bvh>
Partial visit(Bvh& bvh, const Scene* scene, const Vec3u* tri_index, uint32_t index, int depth,
              int parallel) {
  auto& node = bvh.nodes[index];
  // The walk is latency-bound on node loads: request every inner child's
  // lines now, so all but the first have arrived when they are visited.
  for (int i = 0; i < N; ++i)
    if (node.child[i].is_inner()) {
      const char* c = reinterpret_cast<const char*>(&bvh.nodes[node.child[i].index()]);
      for (size_t line = 0; line < sizeof(WideNode<N>); line += 64) __builtin_prefetch(c + line);
    }
  Partial slot[N];
  const auto one_slot = [&](int i) {
    const NodeRef c = node.child[i];
    Partial& p = slot[i];
    if (c.empty()) return;
    if (c.is_leaf()) {
      if constexpr (kGather) {
        p = refit_detail::refit_leaf<kWrite>(bvh.triangles, *scene, tri_index, c.leaf_range());
      } else {
        p.box = node.box(i);
      }
      p.area_cost = double(p.box.half_area()) * c.count();
      p.unit_cost = c.count();
    } else {
      p = visit<kGather, kWrite, N>(bvh, scene, tri_index, c.index(), depth + 1, parallel);
    }
  };
  if (depth < parallel) {
    tbb::parallel_for(0, N, one_slot);
  } else {
    for (int i = 0; i < N; ++i) one_slot(i);
  }
  Partial p;
  const CollapsedInner<N>& col = bvh.collapsed[index];
  // A binary leaf split over slots costs as that leaf: its parts' own leaf
  // costs are left out of the sum and the union's added below.
  unsigned leaf_part = 0;
  for (int r = 0; r < col.split_leaves; ++r)
    for (int i = col.leaf_begin[r]; i < col.leaf_end[r]; ++i) leaf_part |= 1u << i;
  // Slot boxes as vectors for the unions below (min / max are exact, so the
  // unions are AABB::extend's bits).
  __m128 lo[N], hi[N];
  VecBox all;
  for (int i = 0; i < N; ++i) {
    if (node.child[i].empty()) continue;
    if constexpr (kGather) node.set_box(i, slot[i].box);
    lo[i] = refit_detail::load3(slot[i].box.min);
    hi[i] = refit_detail::load3(slot[i].box.max);
    all.extend(lo[i], hi[i]);
    if (!(leaf_part >> i & 1u)) p.area_cost += slot[i].area_cost;
    p.unit_cost += slot[i].unit_cost;
    p.valid = p.valid && slot[i].valid;
  }
  p.box = all.aabb();
  p.area_cost += double(p.box.half_area());
  p.unit_cost += 1.0;
  for (int r = 0; r < col.count; ++r) {
    VecBox b;  // collapsed ranges hold no empty slot
    for (int i = col.begin[r]; i < col.end[r]; ++i) b.extend(lo[i], hi[i]);
    p.area_cost += double(b.aabb().half_area());
    p.unit_cost += 1.0;
  }
  for (int r = 0; r < col.split_leaves; ++r) {
    VecBox b;
    uint32_t count = 0;
    for (int i = col.leaf_begin[r]; i < col.leaf_end[r]; ++i) {
      b.extend(lo[i], hi[i]);
      count += node.child[i].count();
    }
    p.area_cost += double(b.aabb().half_area()) * count;
  }
  return p;
}

// A wide level spans about log2(N) binary levels.
template <int N>
int wide_parallel_depth(size_t triangles) {
  constexpr int kLevels = N == 8 ? 3 : 2;
  return (refit_detail::parallel_depth(triangles) + kLevels - 1) / kLevels;
}

// The whole tree as one leaf: its box and cost from its triangles.
template <bool kGather, RefitTriangles kWrite, int N, typename Bvh>
Partial visit_root(Bvh& bvh, const Scene* scene, const Vec3u* tri_index) {
  if (bvh.root.is_inner())
    return visit<kGather, kWrite, N>(bvh, scene, tri_index, bvh.root.index(), 0,
                                     wide_parallel_depth<N>(bvh.triangles.size()));
  Partial p;
  if constexpr (kGather) {
    p = refit_detail::refit_leaf<kWrite>(bvh.triangles, *scene, tri_index, bvh.root.leaf_range());
  }
  p.unit_cost = bvh.root.count();
  p.area_cost = double(p.box.half_area()) * bvh.root.count();
  return p;
}

}  // namespace

template <int N>
RefitResult refit(WideBvh<N>& bvh, const Scene& scene, RefitTriangles triangles,
                  const RefitIndex* index) {
  RefitResult r;
  if (bvh.empty()) return r;
  refit_detail::check_arrays(bvh.triangles, triangles);
  const Vec3u* tri =
      index && index->triangles.size() == bvh.triangles.size() ? index->triangles.data() : nullptr;
  Partial root;
  switch (triangles) {
    case RefitTriangles::kBoth:
      root = visit_root<true, RefitTriangles::kBoth, N>(bvh, &scene, tri);
      break;
    case RefitTriangles::kVerts:
      root = visit_root<true, RefitTriangles::kVerts, N>(bvh, &scene, tri);
      break;
    case RefitTriangles::kEdges:
      root = visit_root<true, RefitTriangles::kEdges, N>(bvh, &scene, tri);
      break;
  }
  r.valid = root.valid;
  r.sah_cost = refit_detail::normalised(root);
  bvh.bounds = root.box;
  return r;
}

template <int N>
double wide_sah_cost(const WideBvh<N>& bvh) {
  if (bvh.empty()) return 0.0;
  // A single-leaf tree has no box stored: its cost is its count whatever the
  // root area (every weight is SA(root) / SA(root) = 1).
  if (bvh.root.is_leaf()) return bvh.root.count();
  return refit_detail::normalised(
      visit_root<false, RefitTriangles::kBoth, N>(bvh, nullptr, nullptr));
}

template RefitResult refit<4>(WideBvh<4>&, const Scene&, RefitTriangles, const RefitIndex*);
template RefitResult refit<8>(WideBvh<8>&, const Scene&, RefitTriangles, const RefitIndex*);
template double wide_sah_cost<4>(const WideBvh<4>&);
template double wide_sah_cost<8>(const WideBvh<8>&);

}  // namespace hprt
