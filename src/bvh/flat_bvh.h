// The traversal layout of the bvh backend: BinaryNode array (root at 0, slot 1
// unused so that every sibling pair starts at an even index, i.e. on a 64-byte
// boundary) and the triangles in leaf order. Empty when the scene has no valid
// triangle; then every ray misses.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#include "bvh/huge_buffer.h"
#include "bvh/leaf_triangles.h"
#include "bvh/node_binary.h"

namespace hprt {

// Allocator for node arrays: 64-byte (cache-line) aligned storage; arrays of
// 2 MiB or more are 2 MiB aligned and advised as transparent huge pages, like
// the triangle arrays (BuildArray): the bottom levels of a large tree are read
// at random, and with 4 KiB pages nearly every such read also missed the TLB.
// Those come from the buffer cache (huge_buffer.h), reused across rebuilds.
template <typename T>
struct CacheAlignedAllocator {
  using value_type = T;
  static constexpr std::size_t kAlign = 64;
  CacheAlignedAllocator() = default;
  template <typename U>
  constexpr CacheAlignedAllocator(const CacheAlignedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) return static_cast<T*>(::operator new(bytes, std::align_val_t(kAlign)));
    return static_cast<T*>(acquire_huge_buffer(bytes));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePage)
      ::operator delete(p, std::align_val_t(kAlign));
    else
      release_huge_buffer(p);
  }
  template <typename U>
  bool operator==(const CacheAlignedAllocator<U>&) const noexcept {
    return true;
  }
};

struct FlatBvh {
  std::vector<BinaryNode, CacheAlignedAllocator<BinaryNode>> nodes;
  LeafTriangles triangles;

  bool empty() const { return nodes.empty(); }
  // Bytes of the traversal layout: nodes + leaf-order triangles + refs.
  size_t memory_bytes() const {
    return nodes.size() * sizeof(BinaryNode) + triangles.memory_bytes();
  }
};

}  // namespace hprt
