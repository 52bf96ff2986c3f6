// Summary statistics of repeated timings and the round-robin harness.
#include "bench/bench_timing.h"

#include <algorithm>
#include <cstdio>

namespace hprt::bench {

TimingStats summarize_ms(std::vector<double> samples_ms) {
  TimingStats t;
  t.repetitions = int(samples_ms.size());
  t.samples_ms = samples_ms;
  if (samples_ms.empty()) return t;
  std::sort(samples_ms.begin(), samples_ms.end());
  const size_t n = samples_ms.size();
  t.median_ms = n % 2 ? samples_ms[n / 2] : 0.5 * (samples_ms[n / 2 - 1] + samples_ms[n / 2]);
  t.min_ms = samples_ms.front();
  t.max_ms = samples_ms.back();
  double sum = 0.0;
  for (double s : samples_ms) sum += s;
  t.mean_ms = sum / double(n);
  return t;
}

std::vector<TimingStats> run_round_robin(const std::vector<RoundRobinJob>& jobs,
                                         const std::function<void()>& after_sample) {
  int max_reps = 0;
  for (const RoundRobinJob& j : jobs) max_reps = std::max(max_reps, j.repetitions);
  std::vector<std::vector<double>> samples(jobs.size());
  for (int r = 0; r < max_reps; ++r)
    for (size_t i = 0; i < jobs.size(); ++i)
      if (r < jobs[i].repetitions) {
        samples[i].push_back(jobs[i].sample(r));
        if (after_sample) after_sample();
      }
  std::vector<TimingStats> stats;
  stats.reserve(jobs.size());
  for (std::vector<double>& s : samples) stats.push_back(summarize_ms(std::move(s)));
  return stats;
}

std::string format_median_range(const TimingStats& t, int decimals) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.*f (%.*f–%.*f)", decimals, t.median_ms, decimals, t.min_ms,
                decimals, t.max_ms);
  return buf;
}

}  // namespace hprt::bench
