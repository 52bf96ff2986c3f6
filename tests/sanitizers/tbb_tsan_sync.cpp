// ThreadSanitizer builds only (HPRT_SANITIZE=thread): makes TSan see the
// happens-before edge at the end of every oneTBB blocking wait. Debian's
// libtbb is not instrumented: a worker finishing the last task of a
// parallel_for/reduce/invoke or task_group releases the wait_context's
// reference count in (instrumented) header code, but the waiting thread
// observes the count in libtbb's wait loop, which TSan cannot see. TSan then
// reports everything the workers read as racing with the waiter freeing it
// afterwards ("memory freed by the main thread, last read by a TBB worker").
// We interpose the two exported wait entry points, call the real ones, and
// add the acquire on the wait_context's counter that libtbb performed.
// Likewise task memory: libtbb's small-object pool hands a freed task's block
// to another thread (seen: two std::threads' parallel_for root tasks), so
// deallocate releases the block and allocate acquires it.
#include <dlfcn.h>
#include <sanitizer/tsan_interface.h>
#include <tbb/task_group.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace {

// oneTBB 2021: class wait_context { uint64_t m_version_and_traits;
// std::atomic<uint64_t> m_ref_count; ... } -- the counter the workers release.
constexpr std::size_t kRefCountOffset = sizeof(std::uint64_t);
static_assert(sizeof(tbb::detail::d1::wait_context) == 2 * sizeof(std::uint64_t),
              "unexpected oneTBB wait_context layout");

void* real(const char* mangled) {
  void* f = ::dlsym(RTLD_NEXT, mangled);
  if (!f) {
    std::fprintf(stderr, "tbb_tsan_sync: %s not found in libtbb\n", mangled);
    std::abort();
  }
  return f;
}

void acquire(tbb::detail::d1::wait_context& w) {
  __tsan_acquire(reinterpret_cast<char*>(&w) + kRefCountOffset);
}

}  // namespace

namespace tbb::detail::r1 {

void __TBB_EXPORTED_FUNC execute_and_wait(d1::task& t, d1::task_group_context& t_ctx,
                                          d1::wait_context& w, d1::task_group_context& w_ctx) {
  using Fn =
      void (*)(d1::task&, d1::task_group_context&, d1::wait_context&, d1::task_group_context&);
  static const Fn f = reinterpret_cast<Fn>(
      real("_ZN3tbb6detail2r116execute_and_waitERNS0_2d14taskERNS2_18task_group_contextERNS2_"
           "12wait_contextES6_"));
  f(t, t_ctx, w, w_ctx);
  acquire(w);
}

void __TBB_EXPORTED_FUNC wait(d1::wait_context& w, d1::task_group_context& ctx) {
  using Fn = void (*)(d1::wait_context&, d1::task_group_context&);
  static const Fn f = reinterpret_cast<Fn>(
      real("_ZN3tbb6detail2r14waitERNS0_2d112wait_contextERNS2_18task_group_contextE"));
  f(w, ctx);
  acquire(w);
}

void* __TBB_EXPORTED_FUNC allocate(d1::small_object_pool*& pool, std::size_t bytes,
                                   const d1::execution_data& ed) {
  using Fn = void* (*)(d1::small_object_pool*&, std::size_t, const d1::execution_data&);
  static const Fn f = reinterpret_cast<Fn>(
      real("_ZN3tbb6detail2r18allocateERPNS0_2d117small_object_poolEmRKNS2_14execution_dataE"));
  void* p = f(pool, bytes, ed);
  __tsan_acquire(p);
  return p;
}

void* __TBB_EXPORTED_FUNC allocate(d1::small_object_pool*& pool, std::size_t bytes) {
  using Fn = void* (*)(d1::small_object_pool*&, std::size_t);
  static const Fn f =
      reinterpret_cast<Fn>(real("_ZN3tbb6detail2r18allocateERPNS0_2d117small_object_poolEm"));
  void* p = f(pool, bytes);
  __tsan_acquire(p);
  return p;
}

void __TBB_EXPORTED_FUNC deallocate(d1::small_object_pool& pool, void* p, std::size_t bytes,
                                    const d1::execution_data& ed) {
  using Fn = void (*)(d1::small_object_pool&, void*, std::size_t, const d1::execution_data&);
  static const Fn f = reinterpret_cast<Fn>(
      real("_ZN3tbb6detail2r110deallocateERNS0_2d117small_object_poolEPvmRKNS2_14execution_dataE"));
  __tsan_release(p);
  f(pool, p, bytes, ed);
}

void __TBB_EXPORTED_FUNC deallocate(d1::small_object_pool& pool, void* p, std::size_t bytes) {
  using Fn = void (*)(d1::small_object_pool&, void*, std::size_t);
  static const Fn f =
      reinterpret_cast<Fn>(real("_ZN3tbb6detail2r110deallocateERNS0_2d117small_object_poolEPvm"));
  __tsan_release(p);
  f(pool, p, bytes);
}

}  // namespace tbb::detail::r1
