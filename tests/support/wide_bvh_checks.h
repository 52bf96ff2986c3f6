// Structural check of a wide layout (WideBvh<N>), shared by the flatten and
// refit tests: every slot box is exactly the union of what it holds (a leaf:
// its triangles, with the scene's current vertices; an inner child: that
// node's slots), empty slots are (+inf, -inf) and come with an empty ref,
// every inner node has at least two children, and the leaves cover every
// leaf-order triangle once.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "bvh/builders/build_tree.h"
#include "bvh/layout/wide_bvh.h"
#include "core/scene.h"

namespace hprt::test {

// "" when all holds, else the first violation. `nodes_reached`, when given,
// gets the number of wide nodes walked.
template <int N>
std::string check_wide(const WideBvh<N>& bvh, const Scene& scene, size_t* nodes_reached = nullptr) {
  if (bvh.empty()) return bvh.nodes.empty() && bvh.triangles.size() == 0 ? "" : "empty root";
  std::vector<int> covered(bvh.triangles.size(), 0);
  std::string err;
  size_t reached = 0;
  const auto leaf_box = [&](NodeRef ref) {
    AABB u;
    for (uint32_t j = ref.index(); j < ref.index() + ref.count(); ++j) {
      if (j >= covered.size() || covered[j]++) {
        err = "leaf range out of range or overlapping";
        return u;
      }
      const PrimRef r = bvh.triangles.refs[j];
      const Vec3u& t = scene.meshes[r.geom_id].triangles[r.prim_id];
      const auto& pos = scene.meshes[r.geom_id].positions;
      const TriangleVerts v = bvh.triangles.triangle(ref.leaf_range(), j);
      if (!(v.v0 == pos[t[0]] && v.v1 == pos[t[1]] && v.v2 == pos[t[2]])) {
        err = "stale triangle data at " + std::to_string(j);
        return u;
      }
      u.extend(v.v0);
      u.extend(v.v1);
      u.extend(v.v2);
    }
    return u;
  };
  const auto walk = [&](auto&& self, uint32_t index, int depth) -> AABB {
    AABB u;
    if (index >= bvh.nodes.size() || depth > kMaxBuildDepth) {
      err = "bad node index or depth";
      return u;
    }
    ++reached;
    const WideNode<N>& n = bvh.nodes[index];
    int children = 0;
    for (int i = 0; i < N && err.empty(); ++i) {
      const AABB slot = n.box(i);
      if (n.child[i].empty()) {
        const float inf = std::numeric_limits<float>::infinity();
        if (!(slot.min == Vec3f{inf} && slot.max == Vec3f{-inf}))
          err = "empty slot without the empty box at node " + std::to_string(index);
        continue;
      }
      ++children;
      const AABB held =
          n.child[i].is_leaf() ? leaf_box(n.child[i]) : self(self, n.child[i].index(), depth + 1);
      if (err.empty() && !(held == slot))
        err = "slot box not exactly its contents at node " + std::to_string(index);
      u.extend(held);
    }
    if (err.empty() && children < 2) err = "inner node with fewer than 2 children";
    return u;
  };
  if (bvh.root.is_leaf()) {
    leaf_box(bvh.root);
  } else {
    walk(walk, bvh.root.index(), 1);
  }
  if (nodes_reached) *nodes_reached = reached;
  if (!err.empty()) return err;
  if (reached != bvh.nodes.size()) return "unreached nodes";
  for (int c : covered)
    if (c != 1) return "a triangle is in no leaf";
  return "";
}

}  // namespace hprt::test
