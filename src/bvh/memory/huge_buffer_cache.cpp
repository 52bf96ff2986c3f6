// BufferCache: freed large buffers, oldest first, kept up to its limits
// while retained. A request takes the smallest cached buffer that fits it
// without wasting more than a third of it (the arrays of successive rebuilds
// differ by a few per cent: node counts change as the mesh deforms), else a
// fresh one. Few, large allocations: one mutex, and a map of the buffers
// handed out to their sizes.
#include <cstdlib>
#include <mutex>
#include <new>
#include <unordered_map>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "bvh/memory/huge_buffer.h"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#endif

namespace hprt {
namespace {

// Under ASan a cached buffer is poisoned until it is handed out again, so a
// use after release is caught as it would be after free().
void poison(void* p, size_t bytes) {
#if defined(__SANITIZE_ADDRESS__)
  ASAN_POISON_MEMORY_REGION(p, bytes);
#else
  (void)p;
  (void)bytes;
#endif
}
void unpoison(void* p, size_t bytes) {
#if defined(__SANITIZE_ADDRESS__)
  ASAN_UNPOISON_MEMORY_REGION(p, bytes);
#else
  (void)p;
  (void)bytes;
#endif
}

// Whether a buffer of `capacity` may serve a request of `need` (both whole
// huge pages): it fits, wasting at most a third of it.
bool serves(size_t capacity, size_t need) {
  return capacity >= need && capacity - need <= capacity / 3;
}

struct Cached {
  void* p;
  size_t capacity;
};

}  // namespace

struct BufferCache::State {
  mutable std::mutex mutex;
  std::vector<Cached> buffers;            // oldest first
  std::unordered_map<void*, size_t> out;  // handed out: capacity
  size_t bytes = 0;
  int retainers = 0;

  void free_all() {
    for (const Cached& c : buffers) {
      unpoison(c.p, c.capacity);
      std::free(c.p);
    }
    buffers.clear();
    bytes = 0;
  }
};

BufferCache::BufferCache(Limits limits) : state_(std::make_unique<State>()), limits_(limits) {
  state_->buffers.reserve(limits_.max_buffers + 1);  // release never allocates
}

BufferCache::~BufferCache() { state_->free_all(); }

// Never destroyed: buffers may be released by other static objects' destructors.
BufferCache& build_buffer_cache() {
  static BufferCache* c = new BufferCache(BufferCache::Limits{});
  return *c;
}

void* BufferCache::acquire(size_t bytes) {
  if (bytes > SIZE_MAX / 2) throw std::bad_alloc();  // no size that wraps below
  const size_t need = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  State& c = *state_;
  bool retaining = false;
  {
    const std::lock_guard lock(c.mutex);
    retaining = c.retainers > 0;
    auto best = c.buffers.end();
    for (auto it = c.buffers.begin(); it != c.buffers.end(); ++it)
      if (serves(it->capacity, need) && (best == c.buffers.end() || it->capacity < best->capacity))
        best = it;
    if (best != c.buffers.end()) {
      const Cached got = *best;
      c.out[got.p] = got.capacity;  // first: if this throws, the cache is unchanged
      c.bytes -= got.capacity;
      c.buffers.erase(best);
      unpoison(got.p, got.capacity);
      return got.p;
    }
  }
  // While retaining, an eighth more than asked, in address space only (pages
  // never touched are never faulted in): arrays that grow a little from one
  // rebuild to the next (an exploding mesh's node count) still fit it later.
  // The slack is dropped where the buffer could not serve its own size again
  // (2 MiB asked, 4 MiB held).
  size_t capacity = retaining ? (need + need / 8 + kHugePage - 1) / kHugePage * kHugePage : need;
  if (!serves(capacity, need)) capacity = need;
  void* p = std::aligned_alloc(kHugePage, capacity);
  if (!p) throw std::bad_alloc();
  if (limits_.advise_huge_pages) advise_huge_pages(p, capacity);
  try {
    const std::lock_guard lock(c.mutex);
    c.out[p] = capacity;
  } catch (...) {
    std::free(p);
    throw;
  }
  return p;
}

void BufferCache::release(void* p) noexcept {
  if (!p) return;
  State& c = *state_;
  {
    const std::lock_guard lock(c.mutex);
    const auto it = c.out.find(p);
    const size_t capacity = it == c.out.end() ? 0 : it->second;
    if (it != c.out.end()) c.out.erase(it);
    if (c.retainers > 0 && capacity > 0 && capacity <= limits_.max_bytes) {
      c.buffers.push_back({p, capacity});
      c.bytes += capacity;
      poison(p, capacity);
      size_t drop = 0;
      while (c.buffers.size() - drop > limits_.max_buffers || c.bytes > limits_.max_bytes) {
        unpoison(c.buffers[drop].p, c.buffers[drop].capacity);
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

size_t BufferCache::bytes() const {
  const std::lock_guard lock(state_->mutex);
  return state_->bytes;
}

bool BufferCache::retained() const {
  const std::lock_guard lock(state_->mutex);
  return state_->retainers > 0;
}

void BufferCache::retain() {
  const std::lock_guard lock(state_->mutex);
  ++state_->retainers;
}

void BufferCache::release_retention() {
  const std::lock_guard lock(state_->mutex);
  if (--state_->retainers == 0) state_->free_all();
}

void trim_heap() noexcept {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace hprt
