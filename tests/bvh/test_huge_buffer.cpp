// Tests of the large build arrays: BuildArray::reset / shrink keep storage,
// fresh large buffers are advised as huge pages, and the buffer cache behind make_huge_buffer
// caches only while a HugeBufferRetention lives, hands a cached buffer to a request of a close size
// only, and empties when the last retention goes.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bvh/memory/build_array.h"
#include "bvh/memory/huge_buffer.h"

namespace hprt::test {
namespace {

constexpr size_t kMiB = size_t{1} << 20;

TEST(BuildArray, ResetKeepsTheStorageOfTheSameSizeOnly) {
  BuildArray<uint32_t> a(1000);
  const uint32_t* p = a.data();
  a[7] = 42;
  a.reset(1000);
  EXPECT_EQ(a.data(), p);
  EXPECT_EQ(a[7], 42u);
  a.reset(2000);
  EXPECT_EQ(a.size(), 2000u);
  a.reset(0);
  EXPECT_TRUE(a.empty());
  EXPECT_EQ(a.data(), nullptr);
}

// The VmFlags of the mapping of /proc/self/smaps that holds address p ("" if none).
std::string vm_flags_at(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const auto a = reinterpret_cast<uintptr_t>(p);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= a && a < hi;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

TEST(HugeBuffer, FreshLargeBuffersAreAdvisedAsHugePages) {
#if !defined(__linux__) || !defined(MADV_HUGEPAGE)
  GTEST_SKIP() << "no transparent huge pages here";
#else
  if (!huge_pages_enabled()) GTEST_SKIP() << "HPRT_HUGE_PAGES=0 in the environment";
  auto b = make_huge_buffer<uint8_t>(8 * kMiB);
  // Its whole 2 MiB pages: "hg" (VM_HUGEPAGE) in the mapping's flags.
  const std::string flags = vm_flags_at(b.get() + kHugePage);
  ASSERT_FALSE(flags.empty());
  EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;
#endif
}

TEST(BuildArray, ShrinkKeepsThePrefix) {
  BuildArray<int> a(10);
  for (int i = 0; i < 10; ++i) a[size_t(i)] = i;
  a.shrink(4);
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(a[3], 3);
  a.shrink(8);  // never grows
  EXPECT_EQ(a.size(), 4u);
}

TEST(HugeBufferCache, FreesWithoutARetention) {
  ASSERT_EQ(huge_buffer_cache_bytes(), 0u);
  { auto b = make_huge_buffer<uint8_t>(8 * kMiB); }
  EXPECT_EQ(huge_buffer_cache_bytes(), 0u);
}

// retained() follows the count of retentions (a build trims the heap only
// when no retention lives: builder_parallel.cpp).
TEST(HugeBufferCache, RetainedWhileAnyRetentionLives) {
  EXPECT_FALSE(build_buffer_cache().retained());
  {
    HugeBufferRetention a;
    EXPECT_TRUE(build_buffer_cache().retained());
    {
      HugeBufferRetention b;
      EXPECT_TRUE(build_buffer_cache().retained());
    }
    EXPECT_TRUE(build_buffer_cache().retained());
  }
  EXPECT_FALSE(build_buffer_cache().retained());
}

TEST(HugeBufferCache, ReusesACloseSizeWhileRetainedAndEmptiesAfter) {
  {
    HugeBufferRetention retain;
    uint8_t* first = nullptr;
    {
      auto b = make_huge_buffer<uint8_t>(9 * kMiB);
      first = b.get();
      EXPECT_EQ(reinterpret_cast<uintptr_t>(first) % kHugePage, 0u);
    }
    // Whole 2 MiB pages, with some slack for a later, slightly larger request.
    const size_t cached = huge_buffer_cache_bytes();
    EXPECT_GE(cached, 10 * kMiB);
    EXPECT_LE(cached, 12 * kMiB);
    EXPECT_EQ(cached % kHugePage, 0u);
    {
      // Much smaller: not handed the cached buffer (it would waste most of it).
      auto small = make_huge_buffer<uint8_t>(3 * kMiB);
      EXPECT_NE(small.get(), first);
      EXPECT_EQ(huge_buffer_cache_bytes(), cached);
    }
    const size_t both = huge_buffer_cache_bytes();
    EXPECT_GT(both, cached);
    {
      // A little larger, then a little smaller: the first buffer both times.
      {
        auto again = make_huge_buffer<uint32_t>(10 * kMiB / 4);
        EXPECT_EQ(reinterpret_cast<uint8_t*>(again.get()), first);
      }
      auto again = make_huge_buffer<uint32_t>(7 * kMiB / 4 + 1);
      EXPECT_EQ(reinterpret_cast<uint8_t*>(again.get()), first);
      EXPECT_EQ(huge_buffer_cache_bytes(), both - cached);
      // Larger than anything cached: a fresh one.
      auto big = make_huge_buffer<uint8_t>(20 * kMiB);
      EXPECT_NE(big.get(), first);
    }
    { HugeBufferRetention nested; }
    EXPECT_GT(huge_buffer_cache_bytes(), 0u);  // an outer retention still lives
  }
  EXPECT_EQ(huge_buffer_cache_bytes(), 0u);
}

// Threads taking and giving back buffers at once (TSan runs this: the cache
// is one mutex), each writing its buffer's first and last bytes; every
// buffer handed out is held by one thread at a time.
TEST(HugeBufferCache, ConcurrentAcquireAndRelease) {
  HugeBufferRetention retain;
  std::vector<std::thread> threads;
  std::atomic<int> overlaps{0};
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([t, &overlaps] {
      for (int i = 0; i < 200; ++i) {
        const size_t n = (2 + size_t((t + i) % 3)) * kMiB;
        auto b = make_huge_buffer<uint8_t>(n);
        b[0] = uint8_t(t);
        b[n - 1] = uint8_t(t);
        std::this_thread::yield();
        if (b[0] != uint8_t(t) || b[n - 1] != uint8_t(t)) ++overlaps;
      }
    });
  for (std::thread& th : threads) th.join();
  EXPECT_EQ(overlaps.load(), 0);
  EXPECT_GT(huge_buffer_cache_bytes(), 0u);
}

// The smallest cached size, 2 MiB, serves its own size again (with an
// eighth of slack it would be held as 4 MiB, too large for 2 MiB).
TEST(HugeBufferCache, ExactlyOneHugePageIsReused) {
  HugeBufferRetention retain;
  uint8_t* first = nullptr;
  {
    auto b = make_huge_buffer<uint8_t>(kHugePage);
    first = b.get();
  }
  EXPECT_EQ(huge_buffer_cache_bytes(), kHugePage);
  auto again = make_huge_buffer<uint64_t>(kHugePage / 8);
  EXPECT_EQ(reinterpret_cast<uint8_t*>(again.get()), first);
  EXPECT_EQ(huge_buffer_cache_bytes(), 0u);
}

TEST(HugeBufferCache, SmallBuffersAreNeverCached) {
  HugeBufferRetention retain;
  { auto b = make_huge_buffer<uint8_t>(kHugePage - 1); }
  EXPECT_EQ(huge_buffer_cache_bytes(), 0u);
}

// A cache of its own (as api::ResultMemory holds) is independent of the
// build arrays' one and keeps to its limits: the oldest buffer goes first.
TEST(BufferCache, AnInstanceKeepsToItsOwnLimits) {
  BufferCache cache(
      BufferCache::Limits{.max_buffers = 2, .max_bytes = 8 * kMiB, .advise_huge_pages = false});
  cache.retain();
  void* a = cache.acquire(2 * kMiB);
  void* b = cache.acquire(2 * kMiB);
  void* c = cache.acquire(2 * kMiB);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(a) % kHugePage, 0u);
  cache.release(a);
  cache.release(b);
  EXPECT_EQ(cache.bytes(), 4 * kMiB);
  EXPECT_EQ(huge_buffer_cache_bytes(), 0u);  // not the build arrays' cache
  cache.release(c);                          // a third buffer: the oldest, a, is freed
  EXPECT_EQ(cache.bytes(), 4 * kMiB);
  void* again = cache.acquire(2 * kMiB);
  EXPECT_TRUE(again == b || again == c);
  cache.release(again);
  // Larger than max_bytes: freed at once, never cached.
  cache.release(cache.acquire(10 * kMiB));
  EXPECT_EQ(cache.bytes(), 4 * kMiB);
  cache.release_retention();
  EXPECT_EQ(cache.bytes(), 0u);
}

}  // namespace
}  // namespace hprt::test
