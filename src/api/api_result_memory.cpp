// ResultMemory of the public API: large blocks from a BufferCache of its
// own, retained for its lifetime; no huge-page advice, since results are
// written once in order (no TLB pressure) and a fresh huge page can be slow
// to fault in on a virtual machine (bvh/memory/huge_buffer.h).
#include <cstdlib>
#include <new>

#include "bvh/memory/huge_buffer.h"
#include "hprt/hprt.h"

namespace hprt::api {

struct ResultMemory::Impl {
  BufferCache cache;
  explicit Impl(size_t max_bytes)
      : cache(BufferCache::Limits{
            .max_buffers = 64, .max_bytes = max_bytes, .advise_huge_pages = false}) {
    cache.retain();
  }
};

ResultMemory::ResultMemory(size_t max_bytes) : impl_(std::make_unique<Impl>(max_bytes)) {}
ResultMemory::~ResultMemory() = default;

void* ResultMemory::acquire(size_t bytes) {
  if (bytes >= kHugePage) return impl_->cache.acquire(bytes);
  constexpr size_t kAlign = 64;
  void* p =
      std::aligned_alloc(kAlign, (bytes + kAlign - 1) / kAlign * kAlign + (bytes == 0) * kAlign);
  if (!p) throw std::bad_alloc();
  return p;
}

// The cache frees a pointer it did not hand out (a small block) with free().
void ResultMemory::release(void* p) noexcept { impl_->cache.release(p); }

size_t ResultMemory::cached_bytes() const { return impl_->cache.bytes(); }

}  // namespace hprt::api
