// The benches' shared repetition harness: order of the samples (repetition r
// of every job before r+1 of any), per-job counts, statistics and callbacks.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bench/bench_timing.h"

namespace hprt::bench {
namespace {

TEST(RoundRobin, RepetitionROfEveryJobBeforeRPlusOneOfAny) {
  std::string order;
  auto job = [&order](char name, int reps) {
    return RoundRobinJob{reps, [&order, name](int r) {
                           order += name;
                           order += char('0' + r);
                           return double(r + 1);
                         }};
  };
  int callbacks = 0;
  const std::vector<TimingStats> stats =
      run_round_robin({job('a', 3), job('b', 1), job('c', 2), job('d', 0)}, [&] { ++callbacks; });
  EXPECT_EQ(order, "a0b0c0a1c1a2");
  EXPECT_EQ(callbacks, 6);
  ASSERT_EQ(stats.size(), 4u);
  EXPECT_EQ(stats[0].repetitions, 3);
  EXPECT_EQ(stats[0].median_ms, 2.0);  // samples 1, 2, 3
  EXPECT_EQ(stats[0].min_ms, 1.0);
  EXPECT_EQ(stats[0].max_ms, 3.0);
  EXPECT_EQ(stats[1].repetitions, 1);
  EXPECT_EQ(stats[2].median_ms, 1.5);  // mean of the two middle values
  EXPECT_EQ(stats[3].repetitions, 0);
  EXPECT_TRUE(run_round_robin({}).empty());
}

TEST(RoundRobin, TimedSampleRunsSetupUntimedThenTheCall) {
  int setups = 0, calls = 0;
  auto sample = timed_sample([&] { ++setups; }, [&] { ++calls; });
  const std::vector<TimingStats> stats = run_round_robin({RoundRobinJob{4, sample}});
  EXPECT_EQ(setups, 4);
  EXPECT_EQ(calls, 4);
  EXPECT_EQ(stats[0].repetitions, 4);
  EXPECT_GE(stats[0].min_ms, 0.0);
  EXPECT_LE(stats[0].min_ms, stats[0].median_ms);
  EXPECT_LE(stats[0].median_ms, stats[0].max_ms);
}

}  // namespace
}  // namespace hprt::bench
