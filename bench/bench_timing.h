// Timing of benchmarks: a steady clock around the measured call only (setup
// and loading stay outside), repeated; reports median, min and max in ms.
#pragma once

#include <chrono>
#include <string>
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

// "12.3 (11.9–13.0)": median and range for Markdown cells.
std::string format_median_range(const TimingStats& t, int decimals = 1);

}  // namespace hprt::bench
