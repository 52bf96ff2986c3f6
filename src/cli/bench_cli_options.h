// The options every `hprt bench` subcommand takes (--threads, --repeat,
// --quick, --out) and the common ending: Markdown on stdout, files written,
// their paths on stderr. Shared by cmd_bench.cpp and other bench commands.
#pragma once

#include <CLI/CLI.hpp>

#include "bench/bench_options.h"
#include "bench/report/report_bench.h"

namespace hprt::cli {

struct BenchCliOptions {
  bench::BenchOptions options;
  int repeat = 0;
  CLI::Option* repeat_option = nullptr;
};

void add_bench_common_options(CLI::App& cmd, BenchCliOptions& o);
// Options as given (repeat only when --repeat was passed); checks happen in
// the bench itself (check_bench_options: InputError, exit 2).
bench::BenchOptions finish_bench_options(const BenchCliOptions& o);
// Markdown to stdout, then CSV/JSON into --out (paths listed on stderr).
void emit_bench_report(const bench::BenchReport& report);

}  // namespace hprt::cli
