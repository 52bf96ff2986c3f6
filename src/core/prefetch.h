// Software prefetch of a byte range: requests every cache line of
// [p, p + bytes), at most kMaxPrefetchLines of them (the first ones), so a
// rare large block does not flood the memory system.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/force_inline.h"

namespace hprt {

inline constexpr size_t kMaxPrefetchLines = 16;

// Traversal asks for a few lines of every child it may enter, so the common
// case is written without a loop: a range of up to kFewLinesBytes bytes lies
// within four lines, those of its first byte, the next two and its last byte
// (the middle two clamped to the last byte for shorter ranges).
inline constexpr size_t kFewLinesBytes = 3 * 64 + 1;

HPRT_FORCE_INLINE void prefetch_lines(const void* p, size_t bytes) {
  if (bytes == 0) return;
  const char* b = static_cast<const char*>(p);
  if (bytes <= kFewLinesBytes) {
    const char* last = b + (bytes - 1);
    __builtin_prefetch(b);
    __builtin_prefetch(b + 64 < last ? b + 64 : last);
    __builtin_prefetch(b + 128 < last ? b + 128 : last);
    __builtin_prefetch(last);
    return;
  }
  const uintptr_t start = reinterpret_cast<uintptr_t>(b);
  uintptr_t line = start & ~uintptr_t(63);
  const uintptr_t e = start + bytes, cap = line + 64 * kMaxPrefetchLines;
  for (; line < e && line < cap; line += 64)
    __builtin_prefetch(reinterpret_cast<const void*>(line));
}

// An object that starts on a cache line and spans whole lines (a wide
// node): its lines, unrolled.
template <typename T>
HPRT_FORCE_INLINE void prefetch_aligned(const T* p) {
  static_assert(alignof(T) >= 64 && sizeof(T) % 64 == 0 && sizeof(T) <= 64 * kMaxPrefetchLines);
  const char* b = reinterpret_cast<const char*>(p);
  for (size_t off = 0; off < sizeof(T); off += 64) __builtin_prefetch(b + off);
}

}  // namespace hprt
