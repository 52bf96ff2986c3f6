// Options every `hprt bench` subcommand shares (--threads, --repeat, --quick,
// --out) and their checks: bad values throw InputError naming the option.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace hprt::bench {

// The most repetitions any timing option asks for (bench --repeat, and
// `hprt build`/`hprt trace --repeat`).
inline constexpr int kMaxRepeat = 1000;

struct BenchOptions {
  int threads = 0;            // the "all threads" runs use this many (0 = every hardware thread)
  std::optional<int> repeat;  // repetitions per timing; unset = the bench's default
  bool quick = false;         // a short run (seconds): small inputs, fewer repetitions
  std::string out_dir;        // CSV/JSON (and plots) go here; empty = print only
  bool progress = true;       // progress bar on a terminal (stderr)
};

// Throws OptionError("repeat", ...) for repeat outside [1, kMaxRepeat],
// ("threads", ...) outside [0, kMaxThreads], ("--out", ...) when out_dir exists and is not a
// directory. Creates out_dir (and parents) when missing.
void check_bench_options(const BenchOptions& o);

// The repetitions to use: o.repeat when given, else quick_default or full_default.
int repetitions(const BenchOptions& o, int full_default, int quick_default);

// "1" and the resolved "all threads" count, without duplicates (1 thread
// machines or --threads 1 give one entry).
std::vector<int> thread_counts(const BenchOptions& o);

}  // namespace hprt::bench
