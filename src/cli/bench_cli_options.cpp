// Common bench options and report output.
#include "cli/bench_cli_options.h"

#include <cstdio>
#include <iostream>

namespace hprt::cli {

void add_bench_common_options(CLI::App& cmd, BenchCliOptions& o) {
  cmd.add_option("--threads", o.options.threads,
                 "threads of the multi-threaded runs (0 = all hardware threads); 1-thread "
                 "runs are always made too");
  o.repeat_option =
      cmd.add_option("--repeat", o.repeat, "repetitions per timing (default: the bench's own)");
  cmd.add_flag("--quick", o.options.quick, "a short run (seconds): small inputs, 1 repetition");
  cmd.add_option("--out", o.options.out_dir, "write CSV and JSON (and plots) into this directory");
}

bench::BenchOptions finish_bench_options(const BenchCliOptions& o) {
  bench::BenchOptions b = o.options;
  if (o.repeat_option && o.repeat_option->count() > 0) b.repeat = o.repeat;
  return b;
}

void emit_bench_report(const bench::BenchReport& report) {
  report.write_markdown(std::cout);
  std::cout.flush();
  for (const auto& path : report.write_files()) std::fprintf(stderr, "wrote %s\n", path.c_str());
}

}  // namespace hprt::cli
