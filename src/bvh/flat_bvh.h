// The traversal layout of the bvh backend: BinaryNode array (root at 0, slot 1
// unused so that every sibling pair starts at an even index, i.e. on a 64-byte
// boundary) and the triangles in leaf order. Empty when the scene has no valid
// triangle; then every ray misses.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#include "bvh/leaf_triangles.h"
#include "bvh/node_binary.h"

namespace hprt {

// Minimal allocator returning 64-byte (cache-line) aligned storage.
template <typename T>
struct CacheAlignedAllocator {
  using value_type = T;
  static constexpr std::size_t kAlign = 64;
  CacheAlignedAllocator() = default;
  template <typename U>
  constexpr CacheAlignedAllocator(const CacheAlignedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(kAlign)));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t(kAlign)); }
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
