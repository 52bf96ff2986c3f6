// Trace benchmark. Renders: the scene's camera with its focal length and
// resolution replaced, each backend built once per scene (build excluded),
// render_whitted timed. Ray kinds: the same ray set (validators/ray_sets.h,
// seed 1) through both backends, closest hit for primary, reflection,
// diffuse and random rays, any hit (occluded) for shadow rays, the batch call
// timed; on the scenes and on the large-mesh suite.
#include "bench/bench_trace.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "bench/bench_inputs.h"
#include "bench/bench_timing.h"
#include "bench/trace_suite.h"
#include "bvh/intersect/ray_triangle_exact.h"
#include "core/error.h"
#include "core/hit_check.h"
#include "core/parallel.h"
#include "meshgen/mesh_generators.h"
#include "render/progress.h"
#include "render/whitted.h"
#include "validators/point_sets.h"
#include "validators/ray_sets.h"

#ifndef HPRT_SOURCE_DATA_DIR
#define HPRT_SOURCE_DATA_DIR "data"
#endif

namespace hprt::bench {
namespace {

struct Resolution {
  int width, height;
};

// The options of backend bi (0: the one under test, `ours`; 1: Embree) at a
// thread count. bvh: parallel builder, watertight; embree: medium, robust off.
BackendOptions backend_options(const BackendOptions& ours, size_t bi, int threads) {
  BackendOptions bo = ours;
  if (bi == 1) bo.backend = "embree";
  bo.threads = threads;
  return bo;
}

double mrays(size_t rays, double ms) { return ms > 0 ? double(rays) / (ms * 1e3) : 0.0; }

// Report Table 2's focal lengths; the backends in row and timing order.
constexpr float kFocalsMm[] = {6.0f, 13.0f};
// Index 0 is the backend under test (--backend; bvh by default), its
// columns named bvh_* whichever it is.
constexpr const char* kBackends[] = {"bvh", "embree"};
constexpr RayKind kKinds[] = {RayKind::kPrimary, RayKind::kShadow, RayKind::kReflection,
                              RayKind::kDiffuse, RayKind::kRandom};

// The render table's name of the backend under test: bvh, or its spec.
std::string backend_label(const BackendOptions& ours) { return ours.backend; }

void require_triangles(const std::vector<BenchInput>& inputs) {
  for (const auto& in : inputs)
    if (in.scene.triangle_count() == 0) throw InputError(in.source, "scene has no triangles");
}

// Inputs first, so a missing file fails before any timing.
std::vector<BenchInput> load_inputs(const TraceBenchConfig& config) {
  std::vector<BenchInput> inputs;
  for (const auto& path : config.scenes.empty() ? default_trace_scenes() : config.scenes)
    inputs.push_back(file_input(path));
  require_triangles(inputs);
  return inputs;
}

Suite load_trace_suite(const TraceBenchConfig& config) {
  if (!config.suite) return {};
  const bool quick = config.common.quick;
  const size_t tris = config.suite_tris ? config.suite_tris : (quick ? 20'000 : 1'000'000);
  if (tris > kMaxGenerateTriangles)
    throw OptionError("suite_tris", "at most " + with_commas(kMaxGenerateTriangles) +
                                        " triangles, got " + with_commas(tris));
  Suite suite = load_suite(tris, config.meshes, /*with_default_meshes=*/!quick);
  require_triangles(suite.inputs);
  return suite;
}

Table make_render_table() {
  return Table({{"scene", 0},
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
                {"bvh_over_embree_time", 2}});
}

Table make_rays_table() {
  return Table({{"scene", 0},
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
                {"bvh_over_embree", 3},
                {"bvh_exact_per_mray", 1},
                {"bvh_malformed", 0}});
}

struct RenderRow {
  TimingStats t;
  uint64_t rays = 0;
};

// Render timings of one scene: [focal][resolution][backend][thread index].
using RenderGrid = std::vector<std::vector<std::vector<std::vector<RenderRow>>>>;

// Renders of one camera through each built backend, their repetitions
// alternating (bvh, embree, bvh, ...) so a change of load on a shared
// machine hits both alike; one row per backend.
std::vector<RenderRow> time_camera(const Scene& scene, const Camera& cam,
                                   const std::vector<std::unique_ptr<Intersector>>& built,
                                   int reps) {
  std::vector<RenderRow> out(built.size());
  std::vector<RoundRobinJob> jobs;
  for (size_t bi = 0; bi < built.size(); ++bi)
    jobs.push_back({reps, [&, bi](int) {
                      RenderStats stats;
                      const double ms =
                          time_ms([&] { (void)render_whitted(scene, cam, *built[bi], &stats); });
                      out[bi].rays = stats.rays();
                      return ms;
                    }});
  const std::vector<TimingStats> t = run_round_robin(jobs);
  for (size_t bi = 0; bi < built.size(); ++bi) out[bi].t = t[bi];
  return out;
}

// Answers of the timed backend that failed hprt's checks, since `before`: a
// warning line, so a broken plugin's speed is never read as real.
uint64_t report_malformed(const Intersector& ours, uint64_t before, const std::string& where) {
  const uint64_t now = ours.info().malformed_answers;
  const std::string w = malformed_warning(ours.info().name, now - before);
  if (!w.empty())
    std::fprintf(stderr, "hprt bench trace: warning: %s: %s\n", where.c_str(), w.c_str());
  return now - before;
}

// Per thread count both backends built once (build excluded), then every
// focal length and resolution rendered.
RenderGrid time_renders(const Scene& scene, const std::vector<Resolution>& resolutions,
                        const std::vector<int>& threads, int reps, const BackendOptions& ours,
                        Progress& progress) {
  RenderGrid rr(
      std::size(kFocalsMm),
      std::vector<std::vector<std::vector<RenderRow>>>(
          resolutions.size(), std::vector<std::vector<RenderRow>>(
                                  std::size(kBackends), std::vector<RenderRow>(threads.size()))));
  for (size_t ti = 0; ti < threads.size(); ++ti) {
    run_with_threads(threads[ti], [&] {
      std::vector<std::unique_ptr<Intersector>> built;
      for (size_t bi = 0; bi < std::size(kBackends); ++bi) {
        const BackendOptions bo = backend_options(ours, bi, threads[ti]);
        built.push_back(make_intersector(bo.backend, bo));
        built.back()->build(scene);
      }
      const uint64_t malformed_before = built[0]->info().malformed_answers;
      for (size_t fi = 0; fi < std::size(kFocalsMm); ++fi)
        for (size_t ri = 0; ri < resolutions.size(); ++ri) {
          Camera cam = scene.camera;
          cam.focal_length_mm = kFocalsMm[fi];
          cam.width = resolutions[ri].width;
          cam.height = resolutions[ri].height;
          const std::vector<RenderRow> rows = time_camera(scene, cam, built, reps);
          for (size_t bi = 0; bi < rows.size(); ++bi) {
            rr[fi][ri][bi][ti] = rows[bi];
            progress.advance();
          }
        }
      report_malformed(*built[0], malformed_before,
                       "renders at " + std::to_string(threads[ti]) + " threads");
    });
  }
  return rr;
}

void add_render_rows(Table& render, const BenchInput& in, const RenderGrid& rr,
                     const std::vector<Resolution>& resolutions, const std::vector<int>& threads,
                     const BackendOptions& ours) {
  for (size_t fi = 0; fi < std::size(kFocalsMm); ++fi)
    for (size_t ri = 0; ri < resolutions.size(); ++ri)
      for (size_t bi = 0; bi < std::size(kBackends); ++bi)
        for (size_t ti = 0; ti < threads.size(); ++ti) {
          const RenderRow& x = rr[fi][ri][bi][ti];
          auto row = render.new_row();
          row.set("scene", in.label)
              .set("triangles", in.scene.triangle_count())
              .set("focal_mm", double(kFocalsMm[fi]))
              .set("resolution", std::to_string(resolutions[ri].width) + "x" +
                                     std::to_string(resolutions[ri].height))
              .set("backend", bi == 0 ? backend_label(ours) : kBackends[bi])
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
}

struct QueryTimes {
  TimingStats bvh, embree;
  double exact_per_ray = 0.0;  // triangle tests decided in exact arithmetic (bvh side)
  uint64_t malformed = 0;      // a plugin's malformed answers per repetition (core/hit_check.h)
};

enum class Query { kClosest, kAny, kCount, kInside, kClosestPoint };
const char* to_string(Query q) {
  switch (q) {
    case Query::kAny:
      return "occluded";
    case Query::kCount:
      return "count";
    case Query::kInside:
      return "inside";
    case Query::kClosestPoint:
      return "closest";
    case Query::kClosest:
      break;
  }
  return "intersect";
}

// The batch query of `set` (any hit for shadow rays, closest hit otherwise,
// crossing counts on the random rays) through bvh and embree, their
// repetitions alternating so load changes on a shared machine hit both alike.
QueryTimes time_query(const std::vector<Ray>& set, Query query, const Intersector& bvh,
                      const Intersector& embree, int reps, const std::string& where) {
  std::vector<Hit> hits(set.size());
  std::vector<uint8_t> occluded(set.size());
  std::vector<uint32_t> counts(set.size());
  auto run = [&](const Intersector* b) {
    switch (query) {
      case Query::kAny:
        return b->occluded(set, occluded);
      case Query::kCount:
        return b->count(set, counts);
      case Query::kClosest:
      case Query::kInside:
      case Query::kClosestPoint:
        break;
    }
    b->intersect(set, hits);
  };
  // Embree makes its filter-enabled scene on the first count: not timed.
  if (query == Query::kCount)
    for (const Intersector* b : {&bvh, &embree}) b->count(std::span(set).first(1), counts);
  auto trace = [&](const Intersector* b) { return timed_sample([&, b] { run(b); }); };
  const uint64_t exact_before = exact_fallback_count();
  const uint64_t malformed_before = bvh.info().malformed_answers;
  const std::vector<TimingStats> t = run_round_robin({{reps, trace(&bvh)}, {reps, trace(&embree)}});
  const double runs = double(t[0].repetitions) * double(set.size());
  const uint64_t malformed = report_malformed(bvh, malformed_before, where);
  return {t[0], t[1], runs > 0 ? double(exact_fallback_count() - exact_before) / runs : 0.0,
          t[0].repetitions > 0 ? malformed / uint64_t(t[0].repetitions) : malformed};
}

// The point query of `points` (inside/outside, or the closest point with no
// distance bound) through bvh and embree, repetitions alternating.
QueryTimes time_point_query(const std::vector<Vec3f>& points, Query query, const Intersector& bvh,
                            const Intersector& embree, int reps) {
  std::vector<PointLocation> where(points.size());
  std::vector<ClosestPoint> nearest(points.size());
  auto run = [&](const Intersector* b) {
    if (query == Query::kInside)
      b->locate(points, where);
    else
      b->closest(points, std::numeric_limits<float>::infinity(), nearest);
  };
  auto trace = [&](const Intersector* b) { return timed_sample([&, b] { run(b); }); };
  const std::vector<TimingStats> t = run_round_robin({{reps, trace(&bvh)}, {reps, trace(&embree)}});
  return {t[0], t[1], 0.0};
}

// `kind`: the ray kind, or "points-<kind>" for a point query's rows.
void add_ray_row(Table& rays, const std::string& scene_label, const std::string& kind, Query query,
                 size_t n, int threads, int reps, const QueryTimes& q) {
  const TimingStats &tb = q.bvh, &te = q.embree;
  auto row = rays.new_row();
  row.set("scene", scene_label)
      .set("ray_kind", kind)
      .set("query", to_string(query))
      .set("rays", n)
      .set("threads", threads)
      .set("reps", reps)
      .set("bvh_ms", tb.median_ms)
      .set("bvh_min_ms", tb.min_ms)
      .set("bvh_max_ms", tb.max_ms)
      .set("bvh_mrays_per_s", mrays(n, tb.median_ms))
      .set("embree_ms", te.median_ms)
      .set("embree_min_ms", te.min_ms)
      .set("embree_max_ms", te.max_ms)
      .set("embree_mrays_per_s", mrays(n, te.median_ms));
  if (tb.median_ms > 0) row.set("bvh_over_embree", te.median_ms / tb.median_ms);
  row.set("bvh_exact_per_mray", q.exact_per_ray * 1e6);
  row.set("bvh_malformed", q.malformed);
}

// Mrays/s of every ray kind at one thread count, the same ray set (seed 1)
// through both backends.
// Bytes of each backend's acceleration structure (memory_bytes) per triangle.
struct MemoryRow {
  double bvh_bytes_per_tri = 0.0, embree_bytes_per_tri = 0.0;
};

// Mrays/s of every ray kind at one thread count, the same ray set (seed 1)
// through both backends; returns the structures' sizes.
MemoryRow time_ray_kinds(Table& rays, const BenchInput& in, int threads, size_t n_rays, int reps,
                         const BackendOptions& ours, Progress& progress) {
  return run_with_threads(threads, [&] {
    const BackendOptions bo = backend_options(ours, 0, threads);
    const BackendOptions eo = backend_options(ours, 1, threads);
    auto bvh = make_intersector(bo.backend, bo);
    auto embree = make_intersector(eo.backend, eo);
    // The counting and point queries need the watertight bvh test.
    const bool counts_points =
        ours.backend == "bvh" && bo.triangle_test == TriangleTestKind::kWatertight;
    bvh->build(in.scene);
    embree->build(in.scene);
    for (RayKind kind : kKinds) {
      const std::vector<Ray> set = make_rays(in.scene, kind, n_rays, 1, embree.get());
      const Query query = kind == RayKind::kShadow ? Query::kAny : Query::kClosest;
      const std::string name(to_string(kind));
      const std::string where =
          in.label + ", " + name + " rays, " + std::to_string(threads) + " threads";
      add_ray_row(rays, in.label, name, query, set.size(), threads, reps,
                  time_query(set, query, *bvh, *embree, reps, where));
      // Crossing counts (every hit along the ray) on the same random rays.
      if (kind == RayKind::kRandom && counts_points)
        add_ray_row(rays, in.label, name, Query::kCount, set.size(), threads, reps,
                    time_query(set, Query::kCount, *bvh, *embree, reps, where));
      progress.advance();
    }
    // Point queries: inside/outside of random points in the scene's box and
    // of points on the surface; closest points (fewer: each is a search).
    for (PointKind kind : {PointKind::kRandom, PointKind::kNear}) {
      if (!counts_points) break;
      const std::string name = "points-" + std::string(to_string(kind));
      const std::vector<Vec3f> points = make_points(in.scene, kind, n_rays, 1);
      add_ray_row(rays, in.label, name, Query::kInside, points.size(), threads, reps,
                  time_point_query(points, Query::kInside, *bvh, *embree, reps));
      const std::vector<Vec3f> few(points.begin(),
                                   points.begin() + std::max<size_t>(1, points.size() / 10));
      add_ray_row(rays, in.label, name, Query::kClosestPoint, few.size(), threads, reps,
                  time_point_query(few, Query::kClosestPoint, *bvh, *embree, reps));
    }
    const double tris = double(in.scene.triangle_count());
    return MemoryRow{double(bvh->info().memory_bytes) / tris,
                     double(embree->info().memory_bytes) / tris};
  });
}

// Every ray kind at every thread count; one memory row (the structures do not
// depend on the thread count).
void time_input(Table& rays, Table& memory, const BenchInput& in, const std::vector<int>& threads,
                size_t n_rays, int reps, const BackendOptions& ours, Progress& progress) {
  MemoryRow m;
  for (int t : threads) m = time_ray_kinds(rays, in, t, n_rays, reps, ours, progress);
  auto row = memory.new_row();
  row.set("scene", in.label)
      .set("triangles", in.scene.triangle_count())
      .set("bvh_bytes_per_tri", m.bvh_bytes_per_tri)
      .set("embree_bytes_per_tri", m.embree_bytes_per_tri);
  if (m.embree_bytes_per_tri > 0)
    row.set("bvh_over_embree_bytes", m.bvh_bytes_per_tri / m.embree_bytes_per_tri);
}

void add_notes(BenchReport& report, Table& render, Table& rays,
               const std::vector<BenchInput>& inputs, const Suite& suite, bool quick) {
  for (const auto& in : inputs)
    report.add_note(in.label + ": " + in.source + " (" + with_commas(in.scene.triangle_count()) +
                    " triangles, " + std::to_string(in.scene.meshes.size()) + " meshes)");
  for (const auto& in : suite.inputs)
    report.add_note("suite " + in.label + ": " + in.source + " (" +
                    with_commas(in.scene.triangle_count()) + " triangles; ray kinds only)");
  for (const auto& path : suite.skipped)
    report.add_note("suite: " + path + " skipped (absent; give mesh paths with --meshes)");
  render.add_note(
      "render_ms: median of reps of render_whitted (build excluded; bvh and embree repetitions "
      "alternating); rays = primary + "
      "shadow + reflection rays of one render; speedup = 1-thread median / this; "
      "bvh_over_embree_time = bvh render_ms / embree render_ms at the same threads.");
  if (quick)
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
      "primary hits; diffuse = cosine-weighted bounce rays at primary hits (a path tracer's "
      "incoherent secondary rays); random = incoherent origins and directions; query count = "
      "the crossings along each random ray (every hit, Intersector::count; embree: a context "
      "filter function that records and rejects each hit); points-random (uniform in the scene's "
      "box "
      "enlarged by 10%) and points-near (on the triangles, rounded to float), rays = points: "
      "query inside = inside/outside/on the surface (embree: parity of crossings from its counting "
      "filter, on the surface where rtcPointQuery finds distance 0), query closest = the nearest "
      "surface point of a tenth of those points, no distance bound (embree: rtcPointQuery with a "
      "closest-point callback). Scenes and the "
      "large-mesh suite (rows named bumpy-, soup-, sheet- and by mesh file) alike. "
      "bvh_exact_per_mray = triangle tests of the bvh backend's watertight test whose edge "
      "function signs its double error bound could not decide and exact arithmetic did, per "
      "million rays (rays exactly through or within about 1e-15 of an edge or vertex). "
      "bvh_malformed = answers of the timed backend that failed hprt's answer checks, per "
      "repetition (a plugin's; always 0 for bvh).");
}

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
  check_ray_count("rays", config.rays);
  const size_t n_rays = config.rays ? config.rays : (o.quick ? 20'000 : 1'000'000);
  const std::vector<Resolution> resolutions =
      o.quick ? std::vector<Resolution>{{160, 120}, {384, 216}}
              : std::vector<Resolution>{{800, 600}, {1920, 1080}};
  const std::vector<BenchInput> inputs = load_inputs(config);
  const Suite suite = load_trace_suite(config);

  BenchReport report("trace", "Render time and ray throughput (report Table 2, Embree beside)", o);
  report.set_param("threads", threads);
  report.set_param("repetitions", reps);
  report.set_param("rays_per_kind", n_rays);
  BackendOptions ours;
  ours.backend = config.backend;
  ours.layout = config.layout;
  report.set_param("backend", config.backend);
  report.set_param(
      "backends",
      (ours.backend == "bvh" ? "bvh = parallel builder, 32 bins, leaves <= 4, watertight test, " +
                                   std::string(to_string(config.layout)) + " layout"
                             : "bvh columns = " + config.backend) +
          "; embree = rtcCommitScene MEDIUM, robust off");
  Table& render = report.add_table(
      "render", "Whitted render time per scene, focal length, resolution, backend, threads",
      make_render_table());
  Table& rays =
      report.add_table("rays", "Mrays/s per ray kind, bvh against embree", make_rays_table());
  Table& memory =
      report.add_table("memory", "Acceleration structure bytes per triangle, bvh against embree",
                       Table({{"scene", 0},
                              {"triangles", 0},
                              {"bvh_bytes_per_tri", 1},
                              {"embree_bytes_per_tri", 1},
                              {"bvh_over_embree_bytes", 3}}));
  memory.add_note(
      "bytes_per_tri = the backend's memory_bytes / triangles: bvh = nodes and leaf triangle data "
      "of the traversal layout; embree = bytes its device allocated for the committed scene "
      "(rtcSetDeviceMemoryMonitorFunction). bvh_over_embree_bytes < 1: bvh smaller.");

  const size_t steps = inputs.size() * (std::size(kFocalsMm) * resolutions.size() *
                                            std::size(kBackends) * threads.size() +
                                        std::size(kKinds) * threads.size()) +
                       suite.inputs.size() * std::size(kKinds) * threads.size();
  Progress progress("bench trace", steps, o.progress);
  for (const auto& in : inputs) {
    const RenderGrid rr = time_renders(in.scene, resolutions, threads, reps, ours, progress);
    add_render_rows(render, in, rr, resolutions, threads, ours);
    time_input(rays, memory, in, threads, n_rays, reps, ours, progress);
  }
  for (const auto& in : suite.inputs)
    time_input(rays, memory, in, threads, n_rays, reps, ours, progress);
  progress.finish();
  add_notes(report, render, rays, inputs, suite, o.quick);
  return report;
}

}  // namespace hprt::bench
