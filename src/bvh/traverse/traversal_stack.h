// Fixed-capacity traversal stack (no allocation per ray). Binary traversal
// pushes at most one node per level below the root, so depth <= kMaxBuildDepth
// (enforced by every builder) bounds it; Embree sizes its stacks the same way
// (1 + (N - 1) * maxDepth for N-wide nodes, kernels/bvh/bvh_traverser1.h).
#pragma once

#include <cstdint>

#include "bvh/builders/build_tree.h"

namespace hprt {

// A pending node and the ray distance at which the ray enters its box, so a
// popped node farther than the closest hit so far is skipped.
struct StackEntry {
  uint32_t node;
  float entry;
};

template <int kWidth = 2>
class TraversalStack {
 public:
  static constexpr int kCapacity = 1 + (kWidth - 1) * kMaxBuildDepth;

  bool empty() const { return size_ == 0; }
  int size() const { return size_; }
  void push(uint32_t node, float entry) { entries_[size_++] = StackEntry{node, entry}; }
  StackEntry pop() { return entries_[--size_]; }

 private:
  StackEntry entries_[kCapacity];
  int size_ = 0;
};

}  // namespace hprt
