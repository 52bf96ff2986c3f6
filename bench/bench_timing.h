// Timing of benchmarks: a steady clock around the measured call only (setup
// and loading stay outside), repeated; reports median, min and max in ms.
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/stopwatch.h"

namespace hprt::bench {

struct TimingStats {
  int repetitions = 0;
  double median_ms = 0.0;
  double min_ms = 0.0;
  double max_ms = 0.0;
  double mean_ms = 0.0;
  std::vector<double> samples_ms;
};

// Median (mean of the two middle values for an even count), min, max and mean.
TimingStats summarize_ms(std::vector<double> samples_ms);

// Milliseconds spent in `f()`.
template <typename F>
double time_ms(F&& f) {
  const auto start = Clock::now();
  f();
  return ms_since(start);
}

// Calls `setup()` (not timed) then times `f()`, `repetitions` times.
template <typename Setup, typename F>
TimingStats time_repeated(int repetitions, Setup&& setup, F&& f) {
  std::vector<double> samples;
  samples.reserve(repetitions > 0 ? size_t(repetitions) : 0);
  for (int i = 0; i < repetitions; ++i) {
    setup();
    samples.push_back(time_ms(f));
  }
  return summarize_ms(std::move(samples));
}

template <typename F>
TimingStats time_repeated(int repetitions, F&& f) {
  return time_repeated(
      repetitions, [] {}, std::forward<F>(f));
}

// One row of a round-robin run: `sample(r)` runs repetition r (from 0) and
// returns its milliseconds. The job times itself, so what is timed stays its
// own choice (inside a task arena, or a time the callee measured); jobs may
// record more than the time on repetition 0 (tree statistics, memory).
struct RoundRobinJob {
  int repetitions = 0;
  std::function<double(int repetition)> sample;
};

// Runs repetition r of every job before repetition r+1 of any (a job with
// fewer repetitions stops earlier), so a change in the load of a shared
// machine spreads over all rows instead of skewing the few it overlaps.
// `after_sample` (may be empty) runs after each sample, e.g. a progress bar.
// Returns each job's summarize_ms, in job order.
std::vector<TimingStats> run_round_robin(const std::vector<RoundRobinJob>& jobs,
                                         const std::function<void()>& after_sample = {});

// A RoundRobinJob::sample calling `setup()` (not timed) then timing `f()`.
template <typename Setup, typename F>
std::function<double(int)> timed_sample(Setup setup, F f) {
  return [setup = std::move(setup), f = std::move(f)](int) mutable {
    setup();
    return time_ms(f);
  };
}

template <typename F>
std::function<double(int)> timed_sample(F f) {
  return timed_sample([] {}, std::move(f));
}

// "12.3 (11.9–13.0)": median and range for Markdown cells.
std::string format_median_range(const TimingStats& t, int decimals = 1);

}  // namespace hprt::bench
