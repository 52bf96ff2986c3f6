// Uninitialised arrays for one build (trivial types only). Large ones are
// 2 MiB aligned. While a HugeBufferRetention lives (a backend that rebuilds
// every frame holds one), freed large buffers are kept in a small
// process-wide cache and handed out again (huge_buffer_cache.cpp): a
// deforming mesh rebuilt every frame asks for arrays of about the same sizes
// each time, and a cached buffer's pages are faulted in already, where a
// fresh one's are faulted and zeroed by the kernel, a sizeable part of a fast
// rebuild. Only those retained buffers are advised as transparent huge pages
// (fewer TLB misses when the tree is read at random): on a virtual machine
// that hands free memory back to its host, the first touch of a fresh 2 MiB
// page waits for the host, and a one-off build in huge pages took about twice
// as long as in 4 KiB pages (docs/BENCHMARKS.md, machines).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <type_traits>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace hprt {

inline constexpr size_t kHugePage = size_t{2} << 20;

// Advises the whole 2 MiB pages inside [p, p + bytes) as huge pages (advice
// only: failure or no support is harmless). Call before the first touch.
inline void advise_huge_pages(void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const uintptr_t b = (reinterpret_cast<uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t e = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHugePage - 1);
  if (e > b) madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

// A 2 MiB aligned buffer of at least `bytes` (>= kHugePage): a cached one of
// a close capacity, else a fresh one (huge-page advised while retaining).
// Give it back with release_huge_buffer. Only the pages touched are faulted
// in, so a bound may be asked for instead of a size.
void* acquire_huge_buffer(size_t bytes);
// Caches the buffer while a HugeBufferRetention lives (the oldest cached ones
// are freed past the cache's bounds), else frees it.
void release_huge_buffer(void* p) noexcept;
// Bytes held by the cache now.
size_t huge_buffer_cache_bytes();

// While one lives, freed large buffers are cached; when the last one goes,
// the cache is emptied (the memory goes back to the system).
class HugeBufferRetention {
 public:
  HugeBufferRetention();
  ~HugeBufferRetention();
  HugeBufferRetention(const HugeBufferRetention&) = delete;
  HugeBufferRetention& operator=(const HugeBufferRetention&) = delete;
};

// large: from acquire_huge_buffer, else from aligned_alloc.
struct HugeDeleter {
  bool large = false;
  void operator()(void* p) const {
    if (large)
      release_huge_buffer(p);
    else
      std::free(p);
  }
};
template <typename T>
using HugeBuffer = std::unique_ptr<T[], HugeDeleter>;

template <typename T>
HugeBuffer<T> make_huge_buffer(size_t n) {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  static_assert(alignof(T) <= kHugePage);
  const size_t bytes = n * sizeof(T);
  if (bytes >= kHugePage)
    return HugeBuffer<T>(static_cast<T*>(acquire_huge_buffer(bytes)), HugeDeleter{true});
  const size_t align = alignof(T) < 16 ? 16 : alignof(T);
  void* p = std::aligned_alloc(align, (bytes + align - 1) / align * align);
  if (!p) throw std::bad_alloc();
  return HugeBuffer<T>(static_cast<T*>(p));
}

// Allocator for node arrays (build trees and traversal layouts): 64-byte
// (cache-line) aligned storage; arrays of 2 MiB or more come from the buffer
// cache above, like the triangle arrays (BuildArray): reused across rebuilds
// (from malloc, each rebuild's were fresh pages whenever glibc served them by
// mmap), and in huge pages while retained.
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

}  // namespace hprt
