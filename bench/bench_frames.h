// `hprt bench frames`: deformable-scene frame loop per update strategy, bvh
// (rebuild, refit, adaptive) against Embree's dynamic scene (refit and low
// quality) on the same animated input in the same run: update, render and
// total ms per frame (median, min-max), rebuilds, ratios to Embree.
#pragma once

#include <cstddef>
#include <string>

#include "bench/bench_options.h"
#include "bench/report/report_bench.h"

namespace hprt::bench {

struct FramesBenchConfig {
  BenchOptions common;
  // A scene JSON or mesh file; empty = a generated torus of `tris` triangles.
  // A scene with its own animation is run as it is; anything else is run
  // twice, with a gentle wave and with explode applied to every mesh.
  std::string input;
  int frames = 0;                // frames timed after the initial build (0 = 10, --quick 3)
  size_t tris = 0;               // generated input (0 = 1,000,000, --quick 20,000)
  float adaptive_factor = 0.0f;  // bvh adaptive (0 = BackendOptions' default)
  // Adds a row for this backend (bvh, embree or plugin:PATH.so[:OPTIONS]); empty = none.
  std::string backend;
};

// Throws InputError for a bad input or option.
BenchReport run_frames_bench(const FramesBenchConfig& config);

}  // namespace hprt::bench
