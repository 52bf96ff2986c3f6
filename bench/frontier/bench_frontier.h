// `hprt bench frontier`: speed against error. For each configuration (bvh
// builder, bins, leaf size, triangle test; Embree robust off/on): build ms,
// SAH cost relative to sweep, trace Mrays/s, rays wrong according to the
// exact arbiter on hard-case ray sets, and image PSNR against the reference
// render; the Pareto front of (Mrays/s up, wrong rays down), plotted.
#pragma once

#include <string>

#include "bench/bench_options.h"
#include "bench/report/report_bench.h"

namespace hprt::bench {

struct FrontierBenchConfig {
  BenchOptions common;
  std::string mesh;       // a closed mesh file works best (probes); empty = generated sphere
  size_t hard_rays = 0;   // rays per hard-case set; 0 = 2,000 (quick: 200)
  size_t trace_rays = 0;  // primary + random rays timed; 0 = 2 x 250,000 (quick: 2 x 10,000)
  std::string backend;  // adds this backend (bvh, embree or plugin:PATH.so[:OPTIONS]); empty = none
};

BenchReport run_frontier_bench(const FrontierBenchConfig& config);

}  // namespace hprt::bench
