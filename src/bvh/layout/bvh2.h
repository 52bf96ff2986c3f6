// The traversal layout of the bvh backend: BinaryNode array (root at 0, slot 1
// unused so that every sibling pair starts at an even index, i.e. on a 64-byte
// boundary) and the triangles in leaf order. Empty when the scene has no valid
// triangle; then every ray misses.
#pragma once

#include <cstddef>
#include <vector>

#include "bvh/layout/leaf_triangles.h"
#include "bvh/layout/node_binary.h"
#include "bvh/memory/huge_buffer.h"
#include "core/aabb.h"

namespace hprt {

struct Bvh2 {
  std::vector<BinaryNode, CacheAlignedAllocator<BinaryNode>> nodes;
  LeafTriangles triangles;

  bool empty() const { return nodes.empty(); }
  // The root's box: every triangle's (kept by refit).
  AABB bounds() const { return empty() ? AABB{} : AABB(nodes[0].min, nodes[0].max); }
  // Bytes of the traversal layout: nodes + leaf-order triangles + refs.
  size_t memory_bytes() const {
    return nodes.size() * sizeof(BinaryNode) + triangles.memory_bytes();
  }
};

}  // namespace hprt
