// Build tree -> Bvh2. Node pass: a depth-first walk that gives each inner
// node's two children adjacent slots (pairs allocated in the order their
// parents are visited); triangle pass: leaf-order copy of vertices (each leaf
// a verts block, leaf_triangles.h), edges and input (geomID, primID), in
// parallel over the build tree's leaves.
#include "bvh/layout/flatten_bvh2.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <stdexcept>
#include <utility>
#include <vector>

namespace hprt {
namespace {

BinaryNode to_flat(const BuildNode& b) {
  BinaryNode n;
  n.min = b.bounds.min;
  n.max = b.bounds.max;
  n.count = b.count;
  n.index = b.is_leaf() ? b.first : 0;
  return n;
}

// Each leaf-order triangle's data is three dependent reads at random (its
// ref, its vertex indices, its vertices): each is prefetched a few triangles
// before it is needed, once the read before it has been prefetched too.
// Always inlined: GCC deletes a call whose only effects are prefetches.
constexpr size_t kAhead = 8;
[[gnu::always_inline]] inline void prefetch_ahead(const BuildTree& tree, const PrimInfo& prims,
                                                  const Scene& scene, size_t j) {
  const size_t n = tree.prim_order.size();
  if (j + 3 * kAhead < n)
    _mm_prefetch(reinterpret_cast<const char*>(&prims.refs[tree.prim_order[j + 3 * kAhead]]),
                 _MM_HINT_T0);
  if (j + 2 * kAhead < n) {
    const PrimRef r = prims.refs[tree.prim_order[j + 2 * kAhead]];
    _mm_prefetch(reinterpret_cast<const char*>(&scene.meshes[r.geom_id].triangles[r.prim_id]),
                 _MM_HINT_T0);
  }
  if (j + kAhead < n) {
    const PrimRef r = prims.refs[tree.prim_order[j + kAhead]];
    const TriangleMesh& mesh = scene.meshes[r.geom_id];
    const Vec3u& t = mesh.triangles[r.prim_id];
    for (int k = 0; k < 3; ++k)
      _mm_prefetch(reinterpret_cast<const char*>(&mesh.positions[t[k]]), _MM_HINT_T0);
  }
}

// The triangles of the build tree's leaves among nodes [begin, end), each
// leaf one verts block.
template <TriangleArrays kArrays>
void gather_range(const BuildTree& tree, const PrimInfo& prims, const Scene& scene,
                  LeafTriangles& tris, size_t begin, size_t end) {
  for (size_t n = begin; n != end; ++n) {
    const BuildNode& leaf = tree.nodes[n];
    if (!leaf.is_leaf()) continue;
    if (size_t(leaf.first) + leaf.count > tree.prim_order.size())
      throw std::invalid_argument("flatten: leaf range past prim_order");
    const LeafRange block = LeafRange::whole(leaf.first, leaf.count);
    for (uint32_t j = leaf.first; j < leaf.first + leaf.count; ++j) {
      prefetch_ahead(tree, prims, scene, j);
      const PrimRef ref = prims.refs[tree.prim_order[j]];
      const TriangleMesh& mesh = scene.meshes[ref.geom_id];
      const Vec3u& t = mesh.triangles[ref.prim_id];
      const Vec3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
      if constexpr (kArrays != TriangleArrays::kEdges) tris.set_triangle(block, j, a, b, c);
      if constexpr (kArrays != TriangleArrays::kVerts)
        tris.edges[j] = TriangleEdges{a, b - a, c - a};
      tris.refs[j] = ref;
    }
  }
}
}  // namespace

LeafTriangles gather_leaf_triangles(const BuildTree& tree, const PrimInfo& prims,
                                    const Scene& scene, TriangleArrays arrays) {
  LeafTriangles tris;
  gather_leaf_triangles(tree, prims, scene, arrays, tris);
  return tris;
}

void gather_leaf_triangles(const BuildTree& tree, const PrimInfo& prims, const Scene& scene,
                           TriangleArrays arrays, LeafTriangles& tris) {
  tris.allocate(tree.prim_order.size(), arrays);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tree.nodes.size(), 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      switch (arrays) {
                        case TriangleArrays::kBoth:
                          return gather_range<TriangleArrays::kBoth>(tree, prims, scene, tris,
                                                                     r.begin(), r.end());
                        case TriangleArrays::kVerts:
                          return gather_range<TriangleArrays::kVerts>(tree, prims, scene, tris,
                                                                      r.begin(), r.end());
                        case TriangleArrays::kEdges:
                          return gather_range<TriangleArrays::kEdges>(tree, prims, scene, tris,
                                                                      r.begin(), r.end());
                      }
                    });
}

Bvh2 flatten(const BuildTree& tree, const PrimInfo& prims, const Scene& scene,
             TriangleArrays arrays) {
  Bvh2 out = flatten_nodes(tree, prims);
  gather_leaf_triangles(tree, prims, scene, arrays, out.triangles);
  return out;
}

Bvh2 flatten_nodes(const BuildTree& tree, const PrimInfo& prims) {
  Bvh2 out;
  const size_t n = tree.nodes.size();
  if (n == 0) return out;
  if (tree.prim_order.size() != prims.size())
    throw std::invalid_argument("flatten: prim_order does not match PrimInfo");

  // Slot 0: root; slot 1: unused padding; pairs from slot 2 on, so each pair
  // starts at an even index (a 64-byte line in the 64-byte aligned array).
  out.nodes.resize(n == 1 ? 1 : n + 1);
  if (n > 1) out.nodes[1] = BinaryNode{};
  uint32_t next = 2;
  std::vector<std::pair<uint32_t, uint32_t>> todo;  // (build index, flat slot)
  todo.reserve(2 * kMaxBuildDepth + 2);
  todo.emplace_back(0u, 0u);
  size_t visited = 0;
  while (!todo.empty()) {
    const auto [b, f] = todo.back();
    todo.pop_back();
    ++visited;
    const BuildNode& bn = tree.nodes[b];
    BinaryNode& fn = out.nodes[f];
    fn = to_flat(bn);
    if (bn.is_leaf()) {
      if (size_t(bn.first) + bn.count > tree.prim_order.size())
        throw std::invalid_argument("flatten: leaf range past prim_order");
      continue;
    }
    const uint32_t left = b + 1, right = bn.right;
    if (left >= n || right >= n || right <= b || next + 1 >= out.nodes.size())
      throw std::invalid_argument("flatten: malformed build tree");
    fn.index = next;
    next += 2;
    // Push right first so the left subtree is laid out first (depth first).
    todo.emplace_back(right, fn.index + 1);
    todo.emplace_back(left, fn.index);
  }
  if (visited != n || (n > 1 && next != n + 1))
    throw std::invalid_argument("flatten: build tree is not a single binary tree");
  return out;
}

}  // namespace hprt
