// The wide traversal layout of the bvh backend (--layout bvh4|bvh8): WideNode
// array (root at 0) collapsed from the binary build tree, the same leaf-order
// triangles as Bvh2, and, per node, which binary inner nodes were merged
// into it, so the binary SAH cost of docs/ARCHITECTURE.md can still be computed after a
// refit (bvh/refit/refit_wide.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvh/layout/bvh2.h"
#include "bvh/layout/leaf_triangles.h"
#include "bvh/layout/node_wide.h"
#include "core/aabb.h"

namespace hprt {

// The binary inner nodes a wide node stands for besides its own root: each is
// the union of a contiguous range of its slots [begin, end) (collapsing keeps
// every opened node's children adjacent). At most N - 2 of them. And the
// binary leaves split over several slots (slots left free hold parts of the
// node's largest leaves, flatten_wide.cpp): slots [leaf_begin, leaf_end),
// at least 2 each, so at most N / 2.
template <int N>
struct CollapsedInner {
  uint8_t count = 0;
  uint8_t begin[N - 2] = {};
  uint8_t end[N - 2] = {};
  uint8_t split_leaves = 0;
  uint8_t leaf_begin[N / 2] = {};
  uint8_t leaf_end[N / 2] = {};
};

template <int N>
struct WideBvh {
  static constexpr int kWidth = N;

  std::vector<WideNode<N>, CacheAlignedAllocator<WideNode<N>>> nodes;
  std::vector<CollapsedInner<N>, CacheAlignedAllocator<CollapsedInner<N>>> collapsed;  // per node
  NodeRef root;  // nodes[0], or a leaf when the whole tree is one leaf; empty when no triangle
  LeafTriangles triangles;
  AABB bounds;  // of every triangle (the root's box; kept by refit)

  bool empty() const { return root.empty(); }
  size_t memory_bytes() const {
    return nodes.size() * sizeof(WideNode<N>) + triangles.memory_bytes();
  }
};

}  // namespace hprt
