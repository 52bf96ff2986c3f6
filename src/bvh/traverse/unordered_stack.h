// The traversal stack of the queries that need no visiting order (every hit
// along a ray: count, all, inside): a pop takes the entry kDelay below the top while
// the stack is deeper than that, moving the top into its place. Children are
// prefetched when pushed, so the node popped was requested kDelay visits ago
// and its load has overlapped the ones issued since, where a depth-first pop
// would wait for the node it just requested (on 1M-triangle meshes most of
// the traversal's time is those waits). Past the depth-first bound the pops
// take the top, depth first, so the stack stays within twice that bound.
#pragma once

#include <cstdint>

#include "bvh/builders/build_tree.h"
#include "core/force_inline.h"

namespace hprt::detail {

template <int N>
struct UnorderedStack {
  // A wide level pushes at most N entries; the tree is no deeper than the
  // binary tree it was collapsed from.
  static constexpr int kDepthFirstBound = 1 + (N - 1) * kMaxBuildDepth + N;
  static constexpr int kDelay = 4;

  uint64_t entries[2 * kDepthFirstBound];  // left uninitialised: set per ray
  int size = 0;

  bool empty() const { return size == 0; }
  HPRT_FORCE_INLINE void push(uint64_t bits) { entries[size++] = bits; }
  HPRT_FORCE_INLINE uint64_t pop() {
    if (size > kDelay && size < kDepthFirstBound) {
      const uint64_t bits = entries[size - 1 - kDelay];
      entries[size - 1 - kDelay] = entries[size - 1];
      --size;
      return bits;
    }
    return entries[--size];
  }
};

}  // namespace hprt::detail
