// Software prefetch of a byte range: requests every cache line of
// [p, p + bytes), at most kMaxPrefetchLines of them (the first ones), so a
// rare large block does not flood the memory system.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/force_inline.h"

namespace hprt {

inline constexpr size_t kMaxPrefetchLines = 16;

HPRT_FORCE_INLINE void prefetch_lines(const void* p, size_t bytes) {
  const uintptr_t b = reinterpret_cast<uintptr_t>(p);
  uintptr_t line = b & ~uintptr_t(63);
  const uintptr_t e = b + bytes, cap = line + 64 * kMaxPrefetchLines;
  for (; line < e && line < cap; line += 64)
    __builtin_prefetch(reinterpret_cast<const void*>(line));
}

}  // namespace hprt
