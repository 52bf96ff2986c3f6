// The wide traversal node (4 or 8 children): child boxes as structure of
// arrays, one row of N floats per box plane, so one SIMD load brings the same
// plane of all N children and a ray is tested against all of them at once
// (Embree's BVH4/BVH8 AlignedNode, Wald et al. "Embree", SIGGRAPH 2014).
// N = 4: 96 + 32 = 128 bytes (2 cache lines); N = 8: 192 + 64 = 256 (4).
#pragma once

#include <cstdint>
#include <limits>

#include "core/aabb.h"

namespace hprt {

// A child reference: an inner node's index into WideBvh::nodes (count 0), or a
// leaf's triangle range [first, first + count) in leaf order, or empty.
struct NodeRef {
  uint64_t bits = kEmptyBits;

  static constexpr uint64_t kEmptyBits = ~uint64_t(0);
  static constexpr NodeRef inner(uint32_t node) { return NodeRef{node}; }
  static constexpr NodeRef leaf(uint32_t first, uint32_t count) {
    return NodeRef{uint64_t(first) | uint64_t(count) << 32};
  }
  constexpr bool empty() const { return bits == kEmptyBits; }
  constexpr bool is_inner() const { return (bits >> 32) == 0; }
  constexpr bool is_leaf() const { return (bits >> 32) != 0 && !empty(); }
  constexpr uint32_t index() const { return uint32_t(bits); }  // node or first triangle
  constexpr uint32_t count() const { return uint32_t(bits >> 32); }
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
