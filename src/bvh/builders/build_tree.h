// The binary tree every builder returns, in one canonical layout so trees can
// be compared with ==: nodes in depth-first preorder, root at 0, an inner
// node's left child right after it (index + 1) and its right child at `right`;
// a leaf covers prim_order[first, first + count). prim_order holds indices
// into PrimInfo, in leaf order.
#pragma once

#include <cstdint>
#include <vector>

#include "bvh/memory/huge_buffer.h"
#include "core/aabb.h"

namespace hprt {

// Deepest a build tree may be (root depth 1). Every builder falls back to an
// object-median split early enough that no tree exceeds it, so traversal
// stacks can have a fixed size.
constexpr int kMaxBuildDepth = 64;

struct BuildNode {
  AABB bounds;
  uint32_t right = 0;  // inner: index of the right child (left child is this + 1)
  uint32_t first = 0;  // leaf: first index into prim_order
  uint32_t count = 0;  // leaf: number of primitives; 0 marks an inner node
  bool is_leaf() const { return count != 0; }
  bool operator==(const BuildNode&) const = default;
};

// Large ones from the buffer cache (huge_buffer.h), reused by the next rebuild.
using BuildNodes = std::vector<BuildNode, CacheAlignedAllocator<BuildNode>>;
using PrimOrder = std::vector<uint32_t, CacheAlignedAllocator<uint32_t>>;

struct BuildTree {
  BuildNodes nodes;
  PrimOrder prim_order;
  bool operator==(const BuildTree&) const = default;
};

}  // namespace hprt
