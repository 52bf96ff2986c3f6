// `hprt bench build`: the report's Table 1 and more. Per mesh, every builder
// (sweep, presorted, binned, parallel) at 1 thread and all threads, and
// Embree in the same run (rtcCommitScene at LOW/MEDIUM/HIGH, rtcBuildBVH
// building a binary tree whose SAH cost is computed like ours).
#pragma once

#include <string>
#include <vector>

#include "bench/bench_options.h"
#include "bench/report/report_bench.h"

namespace hprt::bench {

struct BuildBenchConfig {
  BenchOptions common;
  std::vector<std::string> meshes;  // files; empty = the generated default set
  bool with_generated = false;      // add the generated set to `meshes`
  bool with_10m = false;            // add a generated 10M-triangle mesh
  // Also time this backend's build() (bvh, embree or plugin:PATH.so[:OPTIONS]),
  // rows "backend:SPEC"; empty = none.
  std::string backend;
};

// Runs the benchmark (progress bar on a terminal); throws InputError for bad
// options or unreadable meshes before any timing starts.
BenchReport run_build_bench(const BuildBenchConfig& config);

}  // namespace hprt::bench
