// Trace benchmark. Renders: the scene's camera with its focal length and
// resolution replaced, each backend built once per scene (build excluded),
// render_whitted timed. Ray kinds: the same ray set (validators/ray_sets.h,
// seed 1) through both backends, closest hit for primary, reflection and
// random rays, any hit (occluded) for shadow rays, the batch call timed.
#include "bench/bench_trace.h"

#include <filesystem>
#include <memory>
#include <optional>

#include "backends/intersector.h"
#include "bench/bench_inputs.h"
#include "bench/bench_timing.h"
#include "core/error.h"
#include "core/parallel.h"
#include "render/progress.h"
#include "render/whitted.h"
#include "validators/ray_sets.h"

#ifndef HPRT_SOURCE_DATA_DIR
#define HPRT_SOURCE_DATA_DIR "data"
#endif

namespace hprt::bench {
namespace {

struct Resolution {
  int width, height;
};

BackendOptions backend_options(const std::string& backend, int threads, BvhLayout layout) {
  BackendOptions bo;
  bo.backend = backend;
  bo.threads = threads;
  bo.layout = layout;
  return bo;  // bvh: parallel builder, watertight; embree: medium, robust off
}

double mrays(size_t rays, double ms) { return ms > 0 ? double(rays) / (ms * 1e3) : 0.0; }

}  // namespace

std::vector<std::string> default_trace_scenes() {
  namespace fs = std::filesystem;
  const std::vector<std::string> names = {"single_13mm.json", "combo.json"};
  for (const std::string& dir :
       {std::string("data/scenes"), std::string(HPRT_SOURCE_DATA_DIR) + "/scenes"}) {
    bool all = true;
    for (const auto& n : names) all = all && fs::exists(fs::path(dir) / n);
    if (all) {
      std::vector<std::string> out;
      for (const auto& n : names) out.push_back((fs::path(dir) / n).string());
      return out;
    }
  }
  throw InputError("data/scenes",
                   "default scenes not found (run from the source tree or give SCENE)");
}

BenchReport run_trace_bench(const TraceBenchConfig& config) {
  const BenchOptions& o = config.common;
  check_bench_options(o);
  const int reps = repetitions(o, 3, 1);
  const std::vector<int> threads = thread_counts(o);
  const size_t n_rays = config.rays ? config.rays : (o.quick ? 20'000 : 1'000'000);
  const std::vector<float> focals = {6.0f, 13.0f};
  const std::vector<Resolution> resolutions =
      o.quick ? std::vector<Resolution>{{160, 120}, {384, 216}}
              : std::vector<Resolution>{{800, 600}, {1920, 1080}};
  const std::vector<std::string> backends = {"bvh", "embree"};
  const std::vector<RayKind> kinds = {RayKind::kPrimary, RayKind::kShadow, RayKind::kReflection,
                                      RayKind::kRandom};

  std::vector<BenchInput> inputs;
  for (const auto& path : config.scenes.empty() ? default_trace_scenes() : config.scenes)
    inputs.push_back(file_input(path));
  for (const auto& in : inputs)
    if (in.scene.triangle_count() == 0) throw InputError(in.source, "scene has no triangles");

  BenchReport report("trace", "Render time and ray throughput (report Table 2, Embree beside)", o);
  report.set_param("threads", threads);
  report.set_param("repetitions", reps);
  report.set_param("rays_per_kind", n_rays);
  report.set_param("backends", "bvh = parallel builder, 32 bins, leaves <= 4, watertight test, " +
                                   std::string(to_string(config.layout)) +
                                   " layout; embree = rtcCommitScene MEDIUM, robust off");
  Table& render = report.add_table(
      "render", "Whitted render time per scene, focal length, resolution, backend, threads",
      Table({{"scene", 0},
             {"triangles", 0},
             {"focal_mm", 0},
             {"resolution", 0},
             {"backend", 0},
             {"threads", 0},
             {"reps", 0},
             {"render_ms", 1},
             {"min_ms", 1},
             {"max_ms", 1},
             {"rays", 0},
             {"mrays_per_s", 2},
             {"speedup", 2},
             {"bvh_over_embree_time", 2}}));
  Table& rays = report.add_table("rays", "Mrays/s per ray kind, bvh against embree",
                                 Table({{"scene", 0},
                                        {"ray_kind", 0},
                                        {"query", 0},
                                        {"rays", 0},
                                        {"threads", 0},
                                        {"reps", 0},
                                        {"bvh_ms", 2},
                                        {"bvh_min_ms", 2},
                                        {"bvh_max_ms", 2},
                                        {"bvh_mrays_per_s", 2},
                                        {"embree_ms", 2},
                                        {"embree_min_ms", 2},
                                        {"embree_max_ms", 2},
                                        {"embree_mrays_per_s", 2},
                                        {"bvh_over_embree", 3}}));

  const size_t steps =
      inputs.size() * (focals.size() * resolutions.size() * backends.size() * threads.size() +
                       kinds.size() * threads.size());
  Progress progress("bench trace", steps, o.progress);

  for (const auto& in : inputs) {
    const Scene& scene = in.scene;
    // --- renders: per thread count both backends built once, then their
    // repetitions alternate (bvh, embree, bvh, ...) for every camera, so a
    // change of load on a shared machine hits both alike.
    struct RenderRow {
      TimingStats t;
      uint64_t rays = 0;
    };
    // [focal][resolution][backend][thread index]
    std::vector<std::vector<std::vector<std::vector<RenderRow>>>> rr(
        focals.size(),
        std::vector<std::vector<std::vector<RenderRow>>>(
            resolutions.size(), std::vector<std::vector<RenderRow>>(
                                    backends.size(), std::vector<RenderRow>(threads.size()))));
    for (size_t ti = 0; ti < threads.size(); ++ti) {
      run_with_threads(threads[ti], [&] {
        std::vector<std::unique_ptr<Intersector>> built;
        for (const auto& backend : backends) {
          built.push_back(
              make_intersector(backend, backend_options(backend, threads[ti], config.layout)));
          built.back()->build(scene);
        }
        for (size_t fi = 0; fi < focals.size(); ++fi)
          for (size_t ri = 0; ri < resolutions.size(); ++ri) {
            Camera cam = scene.camera;
            cam.focal_length_mm = focals[fi];
            cam.width = resolutions[ri].width;
            cam.height = resolutions[ri].height;
            std::vector<std::vector<double>> samples(backends.size());
            for (int r = 0; r < reps; ++r)
              for (size_t bi = 0; bi < backends.size(); ++bi) {
                RenderStats stats;
                samples[bi].push_back(
                    time_ms([&] { (void)render_whitted(scene, cam, *built[bi], &stats); }));
                rr[fi][ri][bi][ti].rays = stats.rays();
              }
            for (size_t bi = 0; bi < backends.size(); ++bi) {
              rr[fi][ri][bi][ti].t = summarize_ms(samples[bi]);
              progress.advance();
            }
          }
      });
    }
    for (size_t fi = 0; fi < focals.size(); ++fi)
      for (size_t ri = 0; ri < resolutions.size(); ++ri)
        for (size_t bi = 0; bi < backends.size(); ++bi)
          for (size_t ti = 0; ti < threads.size(); ++ti) {
            const RenderRow& x = rr[fi][ri][bi][ti];
            auto row = render.new_row();
            row.set("scene", in.label)
                .set("triangles", scene.triangle_count())
                .set("focal_mm", double(focals[fi]))
                .set("resolution", std::to_string(resolutions[ri].width) + "x" +
                                       std::to_string(resolutions[ri].height))
                .set("backend", backends[bi])
                .set("threads", threads[ti])
                .set("reps", x.t.repetitions)
                .set("render_ms", x.t.median_ms)
                .set("min_ms", x.t.min_ms)
                .set("max_ms", x.t.max_ms)
                .set("rays", x.rays)
                .set("mrays_per_s", mrays(x.rays, x.t.median_ms));
            if (ti > 0 && x.t.median_ms > 0)
              row.set("speedup", rr[fi][ri][bi][0].t.median_ms / x.t.median_ms);
            if (bi > 0 && x.t.median_ms > 0)
              row.set("bvh_over_embree_time", rr[fi][ri][0][ti].t.median_ms / x.t.median_ms);
          }
    // --- ray kinds
    for (size_t ti = 0; ti < threads.size(); ++ti) {
      run_with_threads(threads[ti], [&] {
        auto bvh = make_intersector("bvh", backend_options("bvh", threads[ti], config.layout));
        auto embree =
            make_intersector("embree", backend_options("embree", threads[ti], config.layout));
        bvh->build(scene);
        embree->build(scene);
        for (RayKind kind : kinds) {
          const std::vector<Ray> set = make_rays(scene, kind, n_rays, 1, embree.get());
          const bool occ = kind == RayKind::kShadow;
          std::vector<Hit> hits(set.size());
          std::vector<uint8_t> occluded(set.size());
          // Alternating bvh and embree repetitions, so load changes on a
          // shared machine hit both alike.
          std::vector<double> sb, se;
          auto trace = [&](const Intersector& b) {
            return time_ms([&] {
              if (occ)
                b.occluded(set, occluded);
              else
                b.intersect(set, hits);
            });
          };
          for (int r = 0; r < reps; ++r) {
            sb.push_back(trace(*bvh));
            se.push_back(trace(*embree));
          }
          const TimingStats tb = summarize_ms(sb);
          const TimingStats te = summarize_ms(se);
          auto row = rays.new_row();
          row.set("scene", in.label)
              .set("ray_kind", std::string(to_string(kind)))
              .set("query", occ ? "occluded" : "intersect")
              .set("rays", set.size())
              .set("threads", threads[ti])
              .set("reps", reps)
              .set("bvh_ms", tb.median_ms)
              .set("bvh_min_ms", tb.min_ms)
              .set("bvh_max_ms", tb.max_ms)
              .set("bvh_mrays_per_s", mrays(set.size(), tb.median_ms))
              .set("embree_ms", te.median_ms)
              .set("embree_min_ms", te.min_ms)
              .set("embree_max_ms", te.max_ms)
              .set("embree_mrays_per_s", mrays(set.size(), te.median_ms));
          if (tb.median_ms > 0) row.set("bvh_over_embree", te.median_ms / tb.median_ms);
          progress.advance();
        }
      });
    }
  }
  progress.finish();
  for (const auto& in : inputs)
    report.add_note(in.label + ": " + in.source + " (" + with_commas(in.scene.triangle_count()) +
                    " triangles, " + std::to_string(in.scene.meshes.size()) + " meshes)");
  render.add_note(
      "render_ms: median of reps of render_whitted (build excluded; bvh and embree repetitions "
      "alternating); rays = primary + "
      "shadow + reflection rays of one render; speedup = 1-thread median / this; "
      "bvh_over_embree_time = bvh render_ms / embree render_ms at the same threads.");
  if (o.quick)
    render.add_note("--quick: resolutions 160x120 and 384x216 stand in for 800x600 and 1920x1080.");
  render.add_note(
      "The report's Table 2 (High Performance Ray Tracing, 2012: g++ sequential / OpenMP 4 "
      "threads, seconds, its machine) timed its models car, combo and head at 6 and 13 mm; its "
      "combo: 35.73 / 19.93 s at 6 mm, 48.45 / 27.70 s at 13 mm (data/scenes/combo.json is "
      "our own scene of that name, not the report's model).");
  rays.add_note(
      "bvh_over_embree = bvh Mrays/s / embree Mrays/s (> 1: bvh faster). Rays from "
      "validators/ray_sets (seed 1), bvh and embree repetitions alternating: primary = jittered "
      "camera rays in scanline order; "
      "shadow = from primary hits to light 0 (any-hit); reflection = mirror rays at "
      "primary hits; random = incoherent origins and directions.");
  return report;
}

}  // namespace hprt::bench
