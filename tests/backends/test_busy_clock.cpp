// BusyClock (backends/busy_clock.h): time during which at least one call
// ran. Nested and overlapping calls count once; a take while a call runs
// counts up to now and the rest goes to the next take; many threads in and
// out of calls leave it idle and its total within the wall time.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "backends/busy_clock.h"
#include "core/stopwatch.h"

namespace hprt {
namespace {

using namespace std::chrono_literals;

TEST(BusyClock, SequentialCallsAddUp) {
  BusyClock clock;
  for (int i = 0; i < 2; ++i) {
    const BusyClock::Scope s(&clock);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_GE(clock.take_ms(), 19.9);
  EXPECT_EQ(clock.take_ms(), 0.0);  // a take resets it
}

TEST(BusyClock, OverlappingCallsCountOnce) {
  BusyClock clock;
  std::atomic<bool> a_inside{false}, done{false};
  double outer_ms = 0.0;
  std::thread a([&] {
    const auto start = Clock::now();
    {
      const BusyClock::Scope s(&clock);
      a_inside = true;
      while (!done) std::this_thread::yield();
    }
    outer_ms = ms_since(start);
  });
  std::thread b([&] {
    // Enters once a's call has begun, leaves before it ends: nested in it.
    while (!a_inside) std::this_thread::yield();
    {
      const BusyClock::Scope s(&clock);
      std::this_thread::sleep_for(30ms);
    }
    done = true;
  });
  a.join();
  b.join();
  const double busy = clock.take_ms();
  EXPECT_GE(busy, 29.9);
  // a's call alone; b's 30 ms inside it not added again. The clock reads
  // whole microseconds, so its span may exceed the true one by up to 1 us.
  EXPECT_LE(busy, outer_ms + 0.001);
}

TEST(BusyClock, ATakeDuringACallCountsUpToNow) {
  BusyClock clock;
  std::atomic<bool> started{false}, stop{false};
  std::thread a([&] {
    const BusyClock::Scope s(&clock);
    started = true;
    while (!stop) std::this_thread::yield();
  });
  while (!started) std::this_thread::yield();
  std::this_thread::sleep_for(20ms);
  EXPECT_GE(clock.take_ms(), 19.9);
  std::this_thread::sleep_for(10ms);
  stop = true;
  a.join();
  EXPECT_GE(clock.take_ms(), 9.9);
  EXPECT_EQ(clock.take_ms(), 0.0);
}

TEST(BusyClock, ManyThreadsLeaveItIdleWithinTheWallTime) {
  BusyClock clock;
  const auto start = Clock::now();
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 20000; ++i) {
        const BusyClock::Scope s(&clock);
        if (i % 1000 == 0) std::this_thread::yield();
      }
    });
  for (std::thread& t : threads) t.join();
  const double wall = ms_since(start);
  const double busy = clock.take_ms();
  EXPECT_GE(busy, 0.0);
  // Whole microseconds: disjoint busy stretches, each rounded down at both
  // ends, add up to at most the whole span rounded, 1 us over at worst.
  EXPECT_LE(busy, wall + 0.001);
  EXPECT_EQ(clock.take_ms(), 0.0);  // no call left counted as running
}

}  // namespace
}  // namespace hprt
