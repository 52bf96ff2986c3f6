// `hprt bench trace`: the report's Table 2 and more. Whitted render time per
// scene, focal length (6, 13 mm) and resolution (800x600, 1920x1080) for each
// backend at 1 thread and all threads; and Mrays/s per ray kind (primary,
// shadow, reflection, diffuse, random) bvh against embree with the ratio, and
// each structure's bytes per triangle, on the scenes and on the large-mesh
// suite (bench/trace_suite.h).
#pragma once

#include <string>
#include <vector>

#include "bench/bench_options.h"
#include "bench/report/report_bench.h"
#include "bvh/input/build_options.h"

namespace hprt::bench {

struct TraceBenchConfig {
  BenchOptions common;
  std::vector<std::string> scenes;      // scene JSON or mesh files; empty = the default set
  size_t rays = 0;                      // rays per kind; 0 = 1,000,000 (quick: 20,000)
  BvhLayout layout = BvhLayout::kBvh8;  // the bvh backend's traversal layout
  // The backend timed against Embree (its columns are named bvh_*): bvh,
  // embree, or plugin:PATH.so[:OPTIONS].
  std::string backend = "bvh";
  bool suite = true;                // also the large-mesh suite (ray kinds only)
  std::vector<std::string> meshes;  // the suite's mesh files; empty = default_suite_meshes()
  size_t suite_tris = 0;            // generated suite meshes; 0 = 1,000,000 (quick: 20,000)
};

// The default scenes: data/scenes/single_13mm.json (one model) and
// data/scenes/combo.json (five models), found under ./data/scenes or the
// source tree's data/scenes.
std::vector<std::string> default_trace_scenes();

BenchReport run_trace_bench(const TraceBenchConfig& config);

}  // namespace hprt::bench
