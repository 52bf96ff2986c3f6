// Uninitialised arrays for one build (trivial types only). Large ones are
// 2 MiB aligned and advised as transparent huge pages (Linux), so first touch
// costs one fault per 2 MiB instead of one per 4 KiB page.
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

struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};
template <typename T>
using HugeBuffer = std::unique_ptr<T[], FreeDeleter>;

template <typename T>
HugeBuffer<T> make_huge_buffer(size_t n) {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  const size_t bytes = n * sizeof(T);
  const size_t align = bytes >= kHugePage ? kHugePage : alignof(T) < 16 ? 16 : alignof(T);
  void* p = std::aligned_alloc(align, (bytes + align - 1) / align * align);
  if (!p) throw std::bad_alloc();
  if (align == kHugePage) advise_huge_pages(p, bytes);
  return HugeBuffer<T>(static_cast<T*>(p));
}

}  // namespace hprt
