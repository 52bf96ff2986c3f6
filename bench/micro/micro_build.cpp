// BVH build micro-benchmarks: each of our builders (sweep/presorted on 100k
// triangles only, binned and parallel at 1 thread and all threads also on
// 1M) against Embree's rtcCommitScene at build quality LOW and MEDIUM with
// 1 and all threads, on the same in-code noisy sphere. Ours time
// make_prim_info + build (scene to tree, as rtcCommitScene is); Embree's time
// is rtcCommitScene only. Counters: SAH cost (normalised), Mtris/s.
// HPRT_MESH=path adds the same set on a real mesh (loaded once).
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "bvh/builders/builders.h"
#include "core/parallel.h"
#include "core/scene.h"
#include "io/mesh/mesh_reader.h"

namespace {

using hprt::BuilderKind;

// A UV sphere (rows x cols quads, 2 triangles each) with radial noise.
hprt::TriangleMesh noisy_sphere(int rows, int cols) {
  hprt::TriangleMesh m;
  m.name = "noisy sphere";
  uint64_t s = 12345;
  auto rnd = [&] {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return float(s >> 40) / float(1 << 24);
  };
  for (int i = 0; i <= rows; ++i)
    for (int j = 0; j <= cols; ++j) {
      const float th = 3.14159265f * float(i) / rows, ph = 6.2831853f * float(j) / cols;
      const float r = 1.0f + 0.02f * (rnd() - 0.5f) + 0.05f * std::sin(7 * th) * std::cos(5 * ph);
      m.positions.push_back(
          {r * std::sin(th) * std::cos(ph), r * std::cos(th), r * std::sin(th) * std::sin(ph)});
    }
  auto v = [&](int i, int j) { return static_cast<uint32_t>(i * (cols + 1) + j); };
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      m.triangles.push_back(hprt::Vec3u{{v(i, j), v(i + 1, j), v(i + 1, j + 1)}});
      m.triangles.push_back(hprt::Vec3u{{v(i, j), v(i + 1, j + 1), v(i, j + 1)}});
    }
  return m;
}

// Scenes by id: 0 = 100k sphere, 1 = 1M sphere, 2 = $HPRT_MESH.
const hprt::Scene& scene(int id) {
  static std::map<int, std::unique_ptr<hprt::Scene>> cache;
  auto& s = cache[id];
  if (!s) {
    s = std::make_unique<hprt::Scene>();
    if (id == 0) s->add_mesh(noisy_sphere(224, 224));  // 100,352 triangles
    if (id == 1) s->add_mesh(noisy_sphere(708, 708));  // 1,002,528 triangles
    if (id == 2) s->add_mesh(hprt::load_mesh(std::getenv("HPRT_MESH")));
  }
  return *s;
}

int all_threads() { return hprt::resolve_threads(0); }

// CPU time of the whole process (all threads), ms: on a shared machine the
// work done, where wall time also counts waiting for a core.
double process_cpu_ms() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 +
         (u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e3;
}

void set_counters(benchmark::State& state, const hprt::Scene& sc, double sah) {
  state.counters["tris"] = double(sc.triangle_count());
  state.counters["sah"] = sah;
  state.counters["Mtris/s"] = benchmark::Counter(double(sc.triangle_count()) / 1e6,
                                                 benchmark::Counter::kIsIterationInvariantRate);
}

// Args: scene id, builder, threads (0 = all).
void BM_Build(benchmark::State& state) {
  const hprt::Scene& sc = scene(int(state.range(0)));
  hprt::BuildOptions o;
  o.builder = static_cast<BuilderKind>(state.range(1));
  const int threads = state.range(2) ? int(state.range(2)) : all_threads();
  double sah = 0.0, cpu = 0.0;
  for (auto _ : state) {
    hprt::run_with_threads(threads, [&] {
      const double c0 = process_cpu_ms();
      const hprt::PrimInfo p = hprt::make_prim_info(sc);
      const hprt::BuildTree t = hprt::build_tree(p, o);
      benchmark::DoNotOptimize(t.nodes.data());
      cpu += process_cpu_ms() - c0;
      state.PauseTiming();
      sah = hprt::compute_tree_stats(t, p).sah_cost;
      state.ResumeTiming();
    });
  }
  state.SetLabel(std::string(hprt::to_string(o.builder)) + " threads=" + std::to_string(threads));
  set_counters(state, sc, sah);
  state.counters["cpu_ms"] = cpu / double(state.iterations());
}

void BM_PrimInfo(benchmark::State& state) {
  const hprt::Scene& sc = scene(int(state.range(0)));
  const int threads = state.range(1) ? int(state.range(1)) : all_threads();
  for (auto _ : state) {
    hprt::run_with_threads(threads, [&] {
      const hprt::PrimInfo p = hprt::make_prim_info(sc);
      benchmark::DoNotOptimize(p.bounds.data());
    });
  }
  state.SetLabel("threads=" + std::to_string(threads));
}

// Embree's thread count. Embree 3 (TBB tasking) builds in the calling task
// arena, capped by the device's "threads=N" (checked with process vs
// main-thread CPU time). But "threads=N" also installs a process-wide
// tbb::global_control(max_allowed_parallelism, N), replaced by the next
// device created, that would cap OUR builds as well (checked: after
// rtcNewDevice("threads=1"), a task_arena(2) runs on one thread). Without
// "threads=", Embree's LOW (Morton) builder stays on one thread at N = 2
// after a 1-thread build. So: one device per thread count, all created
// together, the all-threads one last (its cap, = all, is the one left), and
// every commit inside run_with_threads(N), the arena our builders get.
RTCDevice embree_device(int threads) {
  static const std::map<int, RTCDevice> devices = [] {
    std::map<int, RTCDevice> d;
    d[1] = rtcNewDevice("threads=1");
    const int all = all_threads();
    if (all != 1) d[all] = rtcNewDevice(("threads=" + std::to_string(all)).c_str());
    return d;
  }();
  return devices.at(threads);
}

// Args: scene id, quality (0 LOW, 1 MEDIUM), threads (0 = all). Manual time:
// rtcCommitScene only.
void BM_Embree(benchmark::State& state) {
  const hprt::Scene& sc = scene(int(state.range(0)));
  const RTCBuildQuality q = state.range(1) == 0 ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
  const int threads = state.range(2) ? int(state.range(2)) : all_threads();
  RTCDevice dev = embree_device(threads);
  double cpu = 0.0;
  for (auto _ : state) {
    RTCScene s = rtcNewScene(dev);
    rtcSetSceneBuildQuality(s, q);
    for (const hprt::TriangleMesh& m : sc.meshes) {
      RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetGeometryBuildQuality(g, q);
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                 m.positions.data(), 0, sizeof(hprt::Vec3f), m.vertex_count());
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.triangles.data(),
                                 0, sizeof(hprt::Vec3u), m.triangle_count());
      rtcCommitGeometry(g);
      rtcAttachGeometry(s, g);
      rtcReleaseGeometry(g);
    }
    const double c0 = process_cpu_ms();
    const auto t0 = std::chrono::steady_clock::now();
    hprt::run_with_threads(threads, [&] { rtcCommitScene(s); });
    const auto t1 = std::chrono::steady_clock::now();
    cpu += process_cpu_ms() - c0;
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    rtcReleaseScene(s);
  }
  state.SetLabel(std::string("embree ") + (state.range(1) == 0 ? "LOW" : "MEDIUM") +
                 " threads=" + std::to_string(threads));
  set_counters(state, sc, 0.0);
  state.counters["cpu_ms"] = cpu / double(state.iterations());
}

void register_all() {
  std::vector<int> scenes = {0, 1};
  if (const char* p = std::getenv("HPRT_MESH"); p && *p) scenes.push_back(2);
  auto common = [](benchmark::internal::Benchmark* b) {
    b->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true)->Iterations(1);
  };
  for (int s : scenes) {
    const std::string tag = s == 0 ? "sphere100k" : (s == 1 ? "sphere1M" : "HPRT_MESH");
    for (int threads : {1, 0})
      common(benchmark::RegisterBenchmark(("PrimInfo/" + tag).c_str(), BM_PrimInfo)
                 ->Args({s, threads}));
    for (BuilderKind k : {BuilderKind::kSweep, BuilderKind::kPresorted, BuilderKind::kBinned,
                          BuilderKind::kParallel, BuilderKind::kMorton}) {
      if (s != 0 && (k == BuilderKind::kSweep || k == BuilderKind::kPresorted)) continue;
      for (int threads : {1, 0}) {
        if (threads == 0 && k != BuilderKind::kParallel && k != BuilderKind::kMorton) continue;
        common(benchmark::RegisterBenchmark(
                   ("Build/" + tag + "/" + std::string(hprt::to_string(k))).c_str(), BM_Build)
                   ->Args({s, int(k), threads}));
      }
    }
    for (int q : {0, 1})
      for (int threads : {1, 0})
        common(benchmark::RegisterBenchmark(("Embree/" + tag).c_str(), BM_Embree)
                   ->Args({s, q, threads})
                   ->UseManualTime());
  }
}

const int registered = (register_all(), 0);

}  // namespace
