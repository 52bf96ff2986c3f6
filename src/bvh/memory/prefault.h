#pragma once
// First touch of a fresh allocation, spread over the threads: a loop that
// then fills it on one thread (a std::vector's resize) takes no page faults,
// which cost about as much as the writes themselves on these machines.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>

namespace hprt {

// Writes a zero byte into every 4 KiB page of raw storage [p, p + bytes)
// (storage that holds no objects yet, e.g. a vector's reserved capacity).
inline void prefault_pages(void* p, size_t bytes) {
  constexpr size_t kPage = 4096;
  unsigned char* const base = static_cast<unsigned char*>(p);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, (bytes + kPage - 1) / kPage, 64),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) base[i * kPage] = 0;
                    });
}

}  // namespace hprt
