// Tree quality against Embree's own generic binned-SAH builder (rtcBuildBVH):
// a binary tree with leaves of 1-4 primitives and the same SAH constants as
// ours (bench/bench_embree_bvh.h), its normalised SAH cost computed exactly as
// tree_stats.cpp does for our trees. Reports both costs, their ratio and both
// build times. Scene: a generated 1M-triangle sphere, or HPRT_MESH=path.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bench/bench_embree_bvh.h"
#include "bvh/builders/builders.h"
#include "core/parallel.h"
#include "io/mesh/generate_mesh.h"
#include "io/scene/scene_reader.h"

namespace {

const hprt::Scene& bench_scene() {
  static std::unique_ptr<hprt::Scene> scene;
  if (!scene) {
    if (const char* path = std::getenv("HPRT_MESH")) {
      scene = std::make_unique<hprt::Scene>(hprt::load_scene(path));
    } else {
      scene = std::make_unique<hprt::Scene>();
      hprt::GenerateSpec spec;
      spec.kind = "sphere";
      spec.tris = 1000000;
      scene->add_mesh(hprt::generate_mesh(spec));
    }
  }
  return *scene;
}

// arg: threads (0 = all)
void BM_SahVsEmbreeBuildBVH(benchmark::State& state) {
  const int threads = int(state.range(0));
  const hprt::Scene& scene = bench_scene();
  const hprt::PrimInfo prims = hprt::make_prim_info(scene);
  hprt::bench::EmbreeBvhBuilder embree(prims, threads);
  hprt::bench::EmbreeBvhResult embree_result;
  double ours_ms = 0.0, ours_sah = 0.0;
  hprt::BuildOptions options;  // parallel, 32 bins, leaves <= 4, C_trav = C_isect = 1
  hprt::run_with_threads(threads, [&] {
    for (auto _ : state) {
      embree_result = embree.build(options);
      const auto t0 = std::chrono::steady_clock::now();
      const hprt::BuildTree tree = hprt::build_tree(prims, options);
      const auto t1 = std::chrono::steady_clock::now();
      ours_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
      ours_sah = hprt::compute_tree_stats(tree, prims).sah_cost;
      state.SetIterationTime((embree_result.build_ms + ours_ms) / 1e3);
    }
  });
  state.counters["embree_ms"] = embree_result.build_ms;
  state.counters["ours_ms"] = ours_ms;
  state.counters["embree_sah"] = embree_result.sah_cost;
  state.counters["ours_sah"] = ours_sah;
  state.counters["sah_ratio"] = ours_sah / embree_result.sah_cost;
  state.counters["threads"] = hprt::resolve_threads(threads);
  state.counters["triangles"] = double(prims.size());
}

BENCHMARK(BM_SahVsEmbreeBuildBVH)
    ->Arg(1)
    ->Arg(0)
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

}  // namespace
