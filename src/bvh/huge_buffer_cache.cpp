// The cache behind make_huge_buffer: freed large buffers, oldest first, kept
// up to kMaxBuffers and kMaxBytes while a HugeBufferRetention lives. A request
// takes the smallest cached buffer that fits it without wasting more than a
// quarter of it (the arrays of successive rebuilds differ by a few per cent:
// node counts change as the mesh deforms), else a fresh one. Few, large
// allocations: one mutex.
#include <cstdlib>
#include <mutex>
#include <new>
#include <vector>

#include "bvh/huge_buffer.h"

namespace hprt {
namespace {

constexpr size_t kMaxBuffers = 32;
constexpr size_t kMaxBytes = size_t{2} << 30;

struct Cached {
  void* p;
  size_t capacity;
};

struct Cache {
  std::mutex mutex;
  std::vector<Cached> buffers;  // oldest first
  size_t bytes = 0;
  int retainers = 0;

  void free_all() {
    for (const Cached& c : buffers) std::free(c.p);
    buffers.clear();
    bytes = 0;
  }
};

// Never destroyed: buffers may be released by other static objects' destructors.
Cache& cache() {
  static Cache* c = new Cache;
  return *c;
}

}  // namespace

void* acquire_huge_buffer(size_t bytes, size_t& capacity) {
  const size_t need = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  {
    Cache& c = cache();
    const std::lock_guard lock(c.mutex);
    auto best = c.buffers.end();
    for (auto it = c.buffers.begin(); it != c.buffers.end(); ++it)
      if (it->capacity >= need && it->capacity - need <= it->capacity / 4 &&
          (best == c.buffers.end() || it->capacity < best->capacity))
        best = it;
    if (best != c.buffers.end()) {
      void* p = best->p;
      capacity = best->capacity;
      c.bytes -= capacity;
      c.buffers.erase(best);
      return p;
    }
  }
  void* p = std::aligned_alloc(kHugePage, need);
  if (!p) throw std::bad_alloc();
  advise_huge_pages(p, need);
  capacity = need;
  return p;
}

void release_huge_buffer(void* p, size_t capacity) {
  if (!p) return;
  Cache& c = cache();
  {
    const std::lock_guard lock(c.mutex);
    if (c.retainers > 0 && capacity <= kMaxBytes) {
      c.buffers.push_back({p, capacity});
      c.bytes += capacity;
      size_t drop = 0;
      while (c.buffers.size() - drop > kMaxBuffers || c.bytes > kMaxBytes) {
        std::free(c.buffers[drop].p);
        c.bytes -= c.buffers[drop].capacity;
        ++drop;
      }
      c.buffers.erase(c.buffers.begin(), c.buffers.begin() + std::ptrdiff_t(drop));
      return;
    }
  }
  std::free(p);
}

size_t huge_buffer_cache_bytes() {
  Cache& c = cache();
  const std::lock_guard lock(c.mutex);
  return c.bytes;
}

HugeBufferRetention::HugeBufferRetention() {
  Cache& c = cache();
  const std::lock_guard lock(c.mutex);
  ++c.retainers;
}

HugeBufferRetention::~HugeBufferRetention() {
  Cache& c = cache();
  const std::lock_guard lock(c.mutex);
  if (--c.retainers == 0) c.free_all();
}

}  // namespace hprt
