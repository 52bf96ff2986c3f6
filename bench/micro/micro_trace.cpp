// Trace throughput micro-benchmark: bvh (watertight and Möller-Trumbore on
// the default bvh8 layout, watertight on the binary bvh2 one) and Embree on
// the same scene and the same ray sets, at 1 and all threads, in
// one run. Scene: a generated 1M-triangle sphere, or HPRT_MESH=path (a bare
// mesh path is framed by the default camera). Counter Mrays/s; the ratio
// bvh/embree is read off rows of the same run.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "core/parallel.h"
#include "io/mesh/generate_mesh.h"
#include "io/scene/scene_reader.h"
#include "validators/ray_sets.h"

namespace {

constexpr size_t kRays = 200000;

const hprt::Scene& bench_scene() {
  static std::unique_ptr<hprt::Scene> scene;
  if (!scene) {
    const char* path = std::getenv("HPRT_MESH");
    if (path) {
      scene = std::make_unique<hprt::Scene>(hprt::load_scene(path));
    } else {
      scene = std::make_unique<hprt::Scene>();
      hprt::GenerateSpec spec;
      spec.kind = "sphere";
      spec.tris = 1000000;
      hprt::TriangleMesh m = hprt::generate_mesh(spec);
      scene->add_mesh(std::move(m));
      scene->camera = hprt::framing_camera(scene->bounds(), hprt::Camera{});
      scene->lights.push_back(hprt::head_light(scene->camera));
    }
  }
  return *scene;
}

// Ray sets are made once with Embree, so every configuration traces the same rays.
const std::vector<hprt::Ray>& rays(hprt::RayKind kind) {
  static std::map<int, std::vector<hprt::Ray>> cache;
  auto& r = cache[int(kind)];
  if (r.empty()) {
    hprt::BackendOptions o;
    auto emb = hprt::make_intersector("embree", o);
    emb->build(bench_scene());
    r = hprt::make_rays(bench_scene(), kind, kRays, 7, emb.get());
  }
  return r;
}

// args: backend (0 bvh watertight, 1 bvh mt, 2 embree, 3 bvh watertight
// binary layout), kind (0 primary,
// 1 random, 2 shadow, 3 reflection), threads (0 = all)
void BM_Trace(benchmark::State& state) {
  const int backend = int(state.range(0));
  const hprt::RayKind kind = state.range(1) == 0   ? hprt::RayKind::kPrimary
                             : state.range(1) == 1 ? hprt::RayKind::kRandom
                             : state.range(1) == 2 ? hprt::RayKind::kShadow
                                                   : hprt::RayKind::kReflection;
  const int threads = int(state.range(2));
  const auto& rs = rays(kind);
  hprt::BackendOptions o;
  o.threads = threads;
  o.triangle_test =
      backend == 1 ? hprt::TriangleTestKind::kMoller : hprt::TriangleTestKind::kWatertight;
  if (backend == 3) o.layout = hprt::BvhLayout::kBvh2;
  std::vector<hprt::Hit> hits(rs.size());
  hprt::run_with_threads(threads, [&] {
    auto isect = hprt::make_intersector(backend == 2 ? "embree" : "bvh", o);
    isect->build(bench_scene());
    isect->intersect(rs, hits);  // warm-up
    for (auto _ : state) {
      isect->intersect(rs, hits);
      benchmark::ClobberMemory();
    }
  });
  state.counters["Mrays/s"] =
      benchmark::Counter(double(rs.size()) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
  state.counters["threads"] = hprt::resolve_threads(threads);
  state.counters["triangles"] = double(bench_scene().triangle_count());
  state.SetLabel(backend == 0   ? "bvh/watertight"
                 : backend == 1 ? "bvh/mt"
                 : backend == 2 ? "embree/medium"
                                : "bvh/watertight/bvh2");
}

BENCHMARK(BM_Trace)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1, 2, 3}, {1, 0}})
    ->ArgNames({"backend", "kind", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

}  // namespace
