// The top of a tree built by parallel tasks (builder_parallel): each task
// returns a Part, either one node with two child parts or a subtree built
// sequentially in preorder (right children relative to its first node, leaf
// ranges already final) into the part's own vector. place_parts stitches
// them into the canonical
// preorder of build_tree.h from the parts' sizes, so the tree never depends
// on which thread built what.
#pragma once

#include <tbb/parallel_invoke.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bvh/builders/build_tree.h"
#include "bvh/memory/huge_buffer.h"

namespace hprt {

struct Part {
  BuildNode node;
  std::unique_ptr<Part> left, right;
  std::span<const BuildNode> subtree;  // non-empty: this part is a finished subtree
  BuildNodes own;                      // the subtree's nodes, where the part holds them
  size_t total = 0;                    // nodes in this part

  const AABB& bounds() const { return subtree.empty() ? node.bounds : subtree.front().bounds; }
};

// Writes `part` into out[offset, offset + part.total) in canonical preorder.
inline void place_part(const Part& part, size_t offset, BuildNode* out) {
  if (!part.subtree.empty()) {
    const uint32_t off = static_cast<uint32_t>(offset);
    for (size_t i = 0; i < part.subtree.size(); ++i) {
      BuildNode nd = part.subtree[i];
      if (!nd.is_leaf()) nd.right += off;
      out[offset + i] = nd;
    }
    return;
  }
  out[offset] = part.node;
  if (part.node.is_leaf()) return;
  const size_t right = offset + 1 + part.left->total;
  out[offset].right = static_cast<uint32_t>(right);
  tbb::parallel_invoke([&] { place_part(*part.left, offset + 1, out); },
                       [&] { place_part(*part.right, right, out); });
}

// tree.nodes = the whole tree of `top`, first touched by the placing tasks.
inline void place_parts(const Part& top, BuildTree& tree) {
  tree.nodes.reserve(top.total);
  advise_huge_pages(tree.nodes.data(), top.total * sizeof(BuildNode));
  tree.nodes.resize(top.total);
  place_part(top, 0, tree.nodes.data());
}

}  // namespace hprt
