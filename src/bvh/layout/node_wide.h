// The wide traversal node (4 or 8 children): child boxes as structure of
// arrays, one row of N floats per box plane, so one SIMD load brings the same
// plane of all N children and a ray is tested against all of them at once
// (Embree's BVH4/BVH8 AlignedNode, Wald et al. "Embree", SIGGRAPH 2014).
// N = 4: 96 + 32 = 128 bytes (2 cache lines); N = 8: 192 + 64 = 256 (4).
#pragma once

#include <cstdint>
#include <limits>

#include "bvh/layout/leaf_triangles.h"
#include "core/aabb.h"

namespace hprt {

// A child reference: an inner node's index into WideBvh::nodes (high half
// 0), or a leaf: its first triangle in leaf order (low half) and, above, its
// count (bits 32-39, 1..255) and where it lies in its verts block
// (LeafTriangles): bits 40-47 first - block_first, bits 48-55 block_count, 0
// when the leaf is its own block; or empty.
struct NodeRef {
  uint64_t bits = kEmptyBits;

  static constexpr uint64_t kEmptyBits = ~uint64_t(0);
  static constexpr uint32_t kMaxLeafCount = 255;
  static constexpr NodeRef inner(uint32_t node) { return NodeRef{node}; }
  // count 1..kMaxLeafCount (callers check).
  static constexpr NodeRef leaf(uint32_t first, uint32_t count) {
    return NodeRef{uint64_t(first) | uint64_t(count) << 32};
  }
  // Triangles [first, first + count) of the block [block_first,
  // block_first + block_count) (at most kMaxLeafCount).
  static constexpr NodeRef leaf_part(uint32_t first, uint32_t count, uint32_t block_first,
                                     uint32_t block_count) {
    return NodeRef{uint64_t(first) | uint64_t(count) << 32 | uint64_t(first - block_first) << 40 |
                   uint64_t(block_count) << 48};
  }
  constexpr bool empty() const { return bits == kEmptyBits; }
  constexpr bool is_inner() const { return (bits >> 32) == 0; }
  constexpr bool is_leaf() const { return (bits >> 32) != 0 && !empty(); }
  constexpr uint32_t index() const { return uint32_t(bits); }  // node or first triangle
  constexpr uint32_t count() const { return uint32_t(bits >> 32) & 0xFF; }
  constexpr LeafRange leaf_range() const {
    const uint32_t block_count = uint32_t(bits >> 48) & 0xFF;
    if (block_count == 0) return LeafRange::whole(index(), count());
    return {index(), count(), index() - (uint32_t(bits >> 40) & 0xFF), block_count};
  }
  constexpr bool operator==(const NodeRef&) const = default;
};

// Rows of `bounds`: lo x, hi x, lo y, hi y, lo z, hi z. An empty slot has the
// box (+inf, -inf) on every axis, which every slab test rejects (the entry
// distance is +inf or the exit -inf whatever the ray's direction signs), so
// traversal needs no per-slot validity check.
template <int N>
struct alignas(64) WideNode {
  static_assert(N == 4 || N == 8, "wide nodes have 4 or 8 children");
  static constexpr int kWidth = N;

  float bounds[6][N];
  NodeRef child[N];

  AABB box(int i) const {
    return AABB(Vec3f{bounds[0][i], bounds[2][i], bounds[4][i]},
                Vec3f{bounds[1][i], bounds[3][i], bounds[5][i]});
  }
  void set_box(int i, const AABB& b) {
    bounds[0][i] = b.min.x;
    bounds[1][i] = b.max.x;
    bounds[2][i] = b.min.y;
    bounds[3][i] = b.max.y;
    bounds[4][i] = b.min.z;
    bounds[5][i] = b.max.z;
  }
  void clear_slot(int i) {
    for (int a = 0; a < 3; ++a) {
      bounds[2 * a][i] = std::numeric_limits<float>::infinity();
      bounds[2 * a + 1][i] = -std::numeric_limits<float>::infinity();
    }
    child[i] = NodeRef{};
  }
};
static_assert(sizeof(WideNode<4>) == 128, "WideNode<4> must stay 2 cache lines");
static_assert(sizeof(WideNode<8>) == 256, "WideNode<8> must stay 4 cache lines");

}  // namespace hprt
