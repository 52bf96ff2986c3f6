// The compact binary traversal node: 32 bytes, so the two children of an inner
// node (always stored next to each other, the left one at an even index) share
// one 64-byte cache line and are fetched and tested together.
#pragma once

#include <cstdint>

#include "core/vec.h"

namespace hprt {

// Packing (as tinybvh's BVHNode / pbrt's LinearBVHNode, 32 bytes):
//   min, index : box minimum and, for an inner node, the index of its first
//                child (the second is index + 1); for a leaf, the index of its
//                first triangle in leaf order (LeafTriangles).
//   max, count : box maximum and the leaf's triangle count; 0 = inner node.
struct alignas(32) BinaryNode {
  Vec3f min;
  uint32_t index = 0;
  Vec3f max;
  uint32_t count = 0;

  constexpr bool is_leaf() const { return count != 0; }
};
static_assert(sizeof(BinaryNode) == 32, "BinaryNode must stay 32 bytes");

}  // namespace hprt
