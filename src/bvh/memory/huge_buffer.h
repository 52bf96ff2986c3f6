// Uninitialised arrays for one build (trivial types only). Large ones are
// 2 MiB aligned and advised as transparent huge pages, as Embree advises its
// own build memory: on virtual machines whose host backs memory lazily a
// fresh 4 KiB page is slow to fault in, and a cold process's first build
// touches a few hundred bytes per triangle of fresh arrays; in 2 MiB pages
// the faults are 512 times fewer, and a tree read at random takes fewer TLB
// misses. Where a host is slow to back a fresh 2 MiB page instead
// (docs/BENCHMARKS.md, machines), HPRT_HUGE_PAGES=0 in the environment turns
// the advice off for the whole process. While a HugeBufferRetention lives
// (a backend that rebuilds every frame holds one), freed large buffers are
// kept in a small process-wide cache and handed out again
// (huge_buffer_cache.cpp): a deforming mesh rebuilt every frame asks for
// arrays of about the same sizes each time, and a cached buffer's pages are
// faulted in already.
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

// False when the environment sets HPRT_HUGE_PAGES=0 (read once).
inline bool huge_pages_enabled() {
  static const bool enabled = [] {
    const char* v = std::getenv("HPRT_HUGE_PAGES");
    return !(v && v[0] == '0' && v[1] == '\0');
  }();
  return enabled;
}

// Advises the whole 2 MiB pages inside [p, p + bytes) as huge pages (advice
// only: failure or no support is harmless), unless huge_pages_enabled() is
// false. Call before the first touch.
inline void advise_huge_pages(void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (!huge_pages_enabled()) return;
  const uintptr_t b = (reinterpret_cast<uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t e = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHugePage - 1);
  if (e > b) madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

// A cache of freed large buffers (huge_buffer_cache.cpp): a request takes a
// cached buffer of a close capacity, else a fresh 2 MiB aligned one; a
// released buffer is kept while the cache is retained (up to its limits,
// the oldest freed first), else freed. The build arrays share one
// (build_buffer_cache()); an api::ResultMemory holds its own.
class BufferCache {
 public:
  struct Limits {
    size_t max_buffers = 32;
    size_t max_bytes = size_t{2} << 30;
    // Advise fresh buffers as transparent huge pages (advise_huge_pages).
    bool advise_huge_pages = true;
  };
  explicit BufferCache(Limits limits);
  ~BufferCache();  // frees the cached buffers (not those handed out)
  BufferCache(const BufferCache&) = delete;
  BufferCache& operator=(const BufferCache&) = delete;

  // At least `bytes` (>= kHugePage is the intended use), 2 MiB aligned,
  // uninitialised. Only the pages touched are faulted in, so a bound may be
  // asked for instead of a size.
  void* acquire(size_t bytes);
  // Caches the buffer while retained, else frees it; a pointer this cache
  // did not hand out is passed to free().
  void release(void* p) noexcept;
  // Bytes held by the cache now.
  size_t bytes() const;
  // Counted: while any retain() is not matched by a release_retention(),
  // freed buffers are cached; the last release_retention() empties the cache.
  void retain();
  void release_retention();
  bool retained() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  Limits limits_;
};

// The build arrays' cache: it caches while a HugeBufferRetention lives.
BufferCache& build_buffer_cache();

// From build_buffer_cache(): a cached buffer of a close capacity, else a
// fresh one (huge-page advised). Give it back with
// release_huge_buffer.
inline void* acquire_huge_buffer(size_t bytes) { return build_buffer_cache().acquire(bytes); }
inline void release_huge_buffer(void* p) noexcept { build_buffer_cache().release(p); }
inline size_t huge_buffer_cache_bytes() { return build_buffer_cache().bytes(); }

// Hands the C library heap's free pages back to the system (glibc's
// malloc_trim; nothing with another C library).
void trim_heap() noexcept;

// While one lives, build_buffer_cache() caches freed large buffers; when the
// last one goes, the cache is emptied (the memory goes back to the system).
class HugeBufferRetention {
 public:
  HugeBufferRetention() { build_buffer_cache().retain(); }
  ~HugeBufferRetention() { build_buffer_cache().release_retention(); }
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
// mmap), and in huge pages.
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
