// Node pass: a depth-first walk over the build tree; each wide node is filled
// by opening its largest-area inner slot in place (its two children take its
// slot and the next), which keeps the slots of every opened binary node
// contiguous, so CollapsedInner can record them as ranges. A wide node's
// inner children get consecutive indices when it is filled. Triangle pass:
// gather_leaf_triangles, as for the binary layout.
#include "bvh/flatten_wide.h"

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <utility>
#include <vector>

#include "bvh/flatten.h"

namespace hprt {
namespace {

struct Filler {
  const BuildTree& tree;
  size_t visited = 0;  // binary nodes placed (wide roots, opened, leaves)

  const BuildNode& node(uint32_t b) const { return tree.nodes[b]; }

  void check_inner(uint32_t b) const {
    const uint32_t n = uint32_t(tree.nodes.size());
    const BuildNode& bn = tree.nodes[b];
    if (b + 1 >= n || bn.right >= n || bn.right <= b)
      throw std::invalid_argument("flatten: malformed build tree");
  }

  // Counts a placed node; a node reached twice (a DAG, not a tree) is caught
  // here before the walk can grow past the tree's size.
  void place() {
    if (++visited > tree.nodes.size())
      throw std::invalid_argument("flatten: build tree is not a single binary tree");
  }

  NodeRef leaf_ref(uint32_t b) {
    const BuildNode& bn = tree.nodes[b];
    if (size_t(bn.first) + bn.count > tree.prim_order.size())
      throw std::invalid_argument("flatten: leaf range past prim_order");
    place();
    return NodeRef::leaf(bn.first, bn.count);
  }
};

}  // namespace

template <int N>
WideBvh<N> flatten_wide(const BuildTree& tree, const PrimInfo& prims, const Scene& scene) {
  WideBvh<N> out;
  const size_t n = tree.nodes.size();
  if (n == 0) return out;
  if (tree.prim_order.size() != prims.size())
    throw std::invalid_argument("flatten: prim_order does not match PrimInfo");

  Filler f{tree};
  if (tree.nodes[0].is_leaf()) {
    out.root = f.leaf_ref(0);
  } else {
    // A wide node holds at least 2 binary nodes' worth of children, so there
    // are at most (n - 1) / 2 of them: reserve once, no reallocation.
    out.nodes.reserve((n - 1) / 2 + 1);
    out.collapsed.reserve((n - 1) / 2 + 1);
    out.nodes.emplace_back();
    out.collapsed.emplace_back();
    out.root = NodeRef::inner(0);
    std::vector<std::pair<uint32_t, uint32_t>> todo;  // (build node, wide node)
    todo.emplace_back(0u, 0u);
    while (!todo.empty()) {
      const auto [b, w] = todo.back();
      todo.pop_back();
      f.check_inner(b);
      f.place();
      uint32_t slot[N];
      int k = 2;
      slot[0] = b + 1;
      slot[1] = f.node(b).right;
      CollapsedInner<N> col;
      while (k < N) {
        int best = -1;
        float best_area = -1.0f;
        for (int i = 0; i < k; ++i) {
          const BuildNode& c = f.node(slot[i]);
          if (!c.is_leaf() && c.bounds.half_area() > best_area) {
            best = i;
            best_area = c.bounds.half_area();
          }
        }
        if (best < 0) break;
        const uint32_t opened = slot[best];
        f.check_inner(opened);
        f.place();
        for (int i = k; i > best + 1; --i) slot[i] = slot[i - 1];
        slot[best] = opened + 1;
        slot[best + 1] = f.node(opened).right;
        ++k;
        // Ranges containing the opened slot grow by one, later ones shift.
        for (int r = 0; r < col.count; ++r) {
          if (col.begin[r] > best) ++col.begin[r];
          if (col.end[r] > best) ++col.end[r];
        }
        col.begin[col.count] = uint8_t(best);
        col.end[col.count] = uint8_t(best + 2);
        ++col.count;
      }
      WideNode<N> node;
      for (int i = 0; i < N; ++i) node.clear_slot(i);
      const size_t pushed_from = todo.size();
      for (int i = 0; i < k; ++i) {
        const BuildNode& c = f.node(slot[i]);
        node.bounds[0][i] = c.bounds.min.x;
        node.bounds[1][i] = c.bounds.max.x;
        node.bounds[2][i] = c.bounds.min.y;
        node.bounds[3][i] = c.bounds.max.y;
        node.bounds[4][i] = c.bounds.min.z;
        node.bounds[5][i] = c.bounds.max.z;
        if (c.is_leaf()) {
          node.child[i] = f.leaf_ref(slot[i]);
        } else {
          const uint32_t child = uint32_t(out.nodes.size());
          out.nodes.emplace_back();
          out.collapsed.emplace_back();
          node.child[i] = NodeRef::inner(child);
          todo.emplace_back(slot[i], child);
        }
      }
      // Visit the first child's subtree first (depth first, in slot order).
      std::reverse(todo.begin() + std::ptrdiff_t(pushed_from), todo.end());
      out.nodes[w] = node;
      out.collapsed[w] = col;
    }
  }
  if (f.visited != n)
    throw std::invalid_argument("flatten: build tree is not a single binary tree");
  out.triangles = gather_leaf_triangles(tree, prims, scene);
  return out;
}

template WideBvh<4> flatten_wide<4>(const BuildTree&, const PrimInfo&, const Scene&);
template WideBvh<8> flatten_wide<8>(const BuildTree&, const PrimInfo&, const Scene&);

}  // namespace hprt
