// Build benchmark. Timed call for our builders: make_prim_info + build_tree
// (boxes, centroids where the builder reads them, and the binary SAH tree;
// flattening to the traversal layout is timed separately once); for Embree:
// the backend's build() (scene, shared-buffer geometry, rtcCommitScene) and
// rtcBuildBVH alone. Each inside a task arena of the row's thread count;
// median, min and max of repetitions, which run round-robin over the rows of
// a mesh.
#include "bench/bench_build.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "backends/intersector.h"
#include "bench/bench_embree_bvh.h"
#include "bench/bench_inputs.h"
#include "bench/bench_timing.h"
#include "bench/cold_build.h"
#include "bvh/builders/builders.h"
#include "bvh/layout/flatten_bvh2.h"
#include "bvh/layout/flatten_wide.h"
#include "core/error.h"
#include "core/parallel.h"
#include "render/progress.h"

namespace hprt::bench {
namespace {

// The triangle data the default backend keeps (the watertight test's).
constexpr TriangleArrays kBackendArrays = TriangleArrays::kVerts;
constexpr size_t kSweepFewerRepsAbove = 300'000;  // sweep is O(n log² n): 1 repetition above

Table make_build_table() {
  return Table({{"mesh", 0},
                {"triangles", 0},
                {"report_model", 0},
                {"builder", 0},
                {"threads", 0},
                {"reps", 0},
                {"build_ms", 1},
                {"min_ms", 1},
                {"max_ms", 1},
                {"mtris_per_s", 2},
                {"speedup", 2},
                {"sah_cost", 2},
                {"sah_vs_embree_bvh", 3},
                {"bytes_per_tri", 1},
                {"nodes", 0},
                {"depth", 0}});
}

struct Timed {
  TimingStats t;
  double sah = -1.0;
  double bytes_per_tri = -1.0;
  size_t nodes = 0;
  int depth = -1;
};

void add_row(Table& table, const BenchInput& in, size_t tris, const std::string& builder,
             int threads, const Timed& r, std::optional<double> one_thread_ms,
             std::optional<double> embree_bvh_sah) {
  auto row = table.new_row();
  row.set("mesh", in.label)
      .set("triangles", tris)
      .set("report_model", in.report_model)
      .set("builder", builder)
      .set("threads", threads)
      .set("reps", r.t.repetitions)
      .set("build_ms", r.t.median_ms)
      .set("min_ms", r.t.min_ms)
      .set("max_ms", r.t.max_ms)
      .set("mtris_per_s", r.t.median_ms > 0 ? double(tris) / (r.t.median_ms * 1e3) : 0.0);
  if (one_thread_ms && r.t.median_ms > 0) row.set("speedup", *one_thread_ms / r.t.median_ms);
  if (r.sah >= 0) row.set("sah_cost", r.sah);
  if (r.sah >= 0 && embree_bvh_sah && *embree_bvh_sah > 0)
    row.set("sah_vs_embree_bvh", r.sah / *embree_bvh_sah);
  if (r.bytes_per_tri >= 0) row.set("bytes_per_tri", r.bytes_per_tri);
  if (r.nodes) row.set("nodes", r.nodes);
  if (r.depth >= 0) row.set("depth", r.depth);
}

// Every builder row of a mesh, in row order: ours, then Embree's commits
// (one per quality), then rtcBuildBVH.
constexpr BuilderKind kBuilders[] = {BuilderKind::kSweep, BuilderKind::kPresorted,
                                     BuilderKind::kBinned, BuilderKind::kParallel,
                                     BuilderKind::kMorton};
constexpr const char* kQualities[] = {"low", "medium", "high"};
constexpr std::string_view kCommitPrefix = "embree-commit-";
constexpr std::string_view kBackendPrefix = "backend:";
// Cold first builds (cold_build.h): the backend and its row's name.
constexpr std::pair<const char*, const char*> kColdBackends[] = {
    {"bvh", "cold-process-bvh"}, {"embree", "cold-process-embree-medium"}};

// Inputs first, so a missing file fails before any timing.
std::vector<BenchInput> load_inputs(const BuildBenchConfig& config) {
  const BenchOptions& o = config.common;
  std::vector<BenchInput> inputs;
  for (const auto& path : config.meshes) inputs.push_back(file_input(path));
  if (config.meshes.empty() || config.with_generated) {
    if (o.quick) {
      inputs.push_back(generated_input(20'000));
    } else {
      for (const auto& m : report_models()) inputs.push_back(generated_input(m.triangles));
    }
  }
  if (config.with_10m) inputs.push_back(generated_input(10'000'000));
  for (const auto& in : inputs)
    if (in.scene.triangle_count() == 0) throw InputError(in.source, "mesh has no triangles");
  return inputs;
}

// Timed calls over all meshes, for the progress bar.
size_t count_steps(const std::vector<BenchInput>& inputs, size_t thread_count, int reps,
                   bool repeat_given, bool with_backend) {
  size_t steps = with_backend ? inputs.size() * thread_count * size_t(reps) : 0;
  for (const auto& in : inputs) {
    const bool sweep_one = in.scene.triangle_count() > kSweepFewerRepsAbove && !repeat_given;
    steps += thread_count * size_t(reps) *
                 (std::size(kBuilders) + 4 + std::size(kColdBackends) - (sweep_one ? 1 : 0)) +
             (sweep_one ? thread_count : 0);
  }
  return steps;
}

// One (builder, thread count) of a mesh.
struct BuildJob {
  std::string builder;
  size_t thread_index = 0;
  int reps = 0;
  Timed result;  // t from the run; the rest from the first repetition
};

// The jobs of a mesh in the order they are timed: rtcBuildBVH, ours, commits.
std::vector<BuildJob> list_jobs(size_t valid, size_t thread_count, int reps, bool repeat_given,
                                const std::string& backend) {
  std::vector<BuildJob> jobs;
  if (!backend.empty())
    for (size_t ti = 0; ti < thread_count; ++ti)
      jobs.push_back({std::string(kBackendPrefix) + backend, ti, reps, {}});
  for (size_t ti = 0; ti < thread_count; ++ti) jobs.push_back({"embree-buildbvh", ti, reps, {}});
  for (BuilderKind b : kBuilders) {
    const int b_reps =
        (b == BuilderKind::kSweep && valid > kSweepFewerRepsAbove && !repeat_given) ? 1 : reps;
    for (size_t ti = 0; ti < thread_count; ++ti)
      jobs.push_back({std::string(to_string(b)), ti, b_reps, {}});
  }
  for (const char* q : kQualities)
    for (size_t ti = 0; ti < thread_count; ++ti)
      jobs.push_back({std::string(kCommitPrefix) + q, ti, reps, {}});
  return jobs;
}

// rtcBuildBVH alone, as Embree's builder measures it; tree statistics once.
std::function<double(int)> embree_bvh_sample(EmbreeBvhBuilder* eb, int t, Timed* res) {
  return [eb, t, res](int rep) {
    const EmbreeBvhResult r = run_with_threads(t, [&] { return eb->build(BuildOptions{}); });
    if (rep == 0) {
      res->sah = r.sah_cost;
      res->nodes = r.nodes;
      res->depth = r.depth;
    }
    return r.build_ms;
  };
}

// The embree backend's build() (geometry + rtcCommitScene); its memory once.
std::function<double(int)> embree_commit_sample(const std::string& quality, int t, Timed* res,
                                                const Scene& scene, size_t valid) {
  BackendOptions bo;
  bo.backend = "embree";
  bo.threads = t;
  bo.embree_quality = quality;
  return [bo, t, res, &scene, valid](int rep) {
    return run_with_threads(t, [&] {
      std::unique_ptr<Intersector> embree = make_intersector("embree", bo);
      const double ms = time_ms([&] { embree->build(scene); });
      if (rep == 0)
        res->bytes_per_tri = valid ? double(embree->info().memory_bytes) / double(valid) : 0.0;
      return ms;
    });
  };
}

// A backend's build() (--backend: hprt's bvh to a traversal-ready tree, or a
// plugin); created outside the timed call; its memory once.
std::function<double(int)> backend_build_sample(const std::string& spec, int t, Timed* res,
                                                const Scene& scene, size_t valid) {
  BackendOptions bo;
  bo.backend = spec;
  bo.threads = t;
  return [bo, t, res, &scene, valid](int rep) {
    return run_with_threads(t, [&] {
      std::unique_ptr<Intersector> backend = make_intersector(bo.backend, bo);
      const double ms = time_ms([&] { backend->build(scene); });
      if (rep == 0)
        res->bytes_per_tri = valid ? double(backend->info().memory_bytes) / double(valid) : 0.0;
      return ms;
    });
  };
}

// make_prim_info + build_tree; tree quality and memory once, outside the
// timed call.
std::function<double(int)> our_build_sample(BuilderKind builder, int t, Timed* res,
                                            const Scene& scene, size_t valid) {
  BuildOptions opts;
  opts.builder = builder;
  return [opts, t, res, &scene, valid](int rep) {
    return run_with_threads(t, [&] {
      std::optional<PrimInfo> prims;
      std::optional<BuildTree> tree;
      const double ms = time_ms([&] {
        prims.emplace(make_prim_info(scene, builder_reads_centroids(opts.builder)));
        tree.emplace(build_tree(*prims, opts));
      });
      if (rep == 0) {
        const TreeStats stats = compute_tree_stats(*tree, *prims);
        res->sah = stats.sah_cost;
        res->nodes = stats.nodes;
        res->depth = stats.depth;
        const Bvh2 flat = flatten(*tree, *prims, scene, kBackendArrays);
        res->bytes_per_tri = valid ? double(flat.memory_bytes()) / double(valid) : 0.0;
      }
      return ms;
    });
  };
}

// Times every job of a mesh, repetitions round-robin over them.
void time_jobs(std::vector<BuildJob>& jobs, const std::vector<int>& threads,
               const PrimInfo& prims_all, const Scene& scene, Progress& progress) {
  const size_t valid = prims_all.size();
  std::vector<std::unique_ptr<EmbreeBvhBuilder>> embree_bvh;
  for (int t : threads) embree_bvh.push_back(std::make_unique<EmbreeBvhBuilder>(prims_all, t));
  std::vector<RoundRobinJob> timed;
  for (BuildJob& job : jobs) {
    const int t = threads[job.thread_index];
    Timed* res = &job.result;
    if (job.builder.rfind(kBackendPrefix, 0) == 0)
      timed.push_back({job.reps, backend_build_sample(job.builder.substr(kBackendPrefix.size()), t,
                                                      res, scene, valid)});
    else if (job.builder == "embree-buildbvh")
      timed.push_back({job.reps, embree_bvh_sample(embree_bvh[job.thread_index].get(), t, res)});
    else if (job.builder.rfind(kCommitPrefix, 0) == 0)
      timed.push_back({job.reps, embree_commit_sample(job.builder.substr(kCommitPrefix.size()), t,
                                                      res, scene, valid)});
    else
      timed.push_back(
          {job.reps, our_build_sample(*parse_builder(job.builder), t, res, scene, valid)});
  }
  const std::vector<TimingStats> stats = run_round_robin(timed, [&] { progress.advance(); });
  for (size_t i = 0; i < jobs.size(); ++i) jobs[i].result.t = stats[i];
}

// Rows of a mesh: our builders, then Embree's commits, then rtcBuildBVH.
void add_rows(Table& table, const BenchInput& in, const std::vector<BuildJob>& jobs,
              const std::vector<int>& threads) {
  auto find = [&](const std::string& name, size_t ti) -> const Timed& {
    for (const BuildJob& j : jobs)
      if (j.builder == name && j.thread_index == ti) return j.result;
    throw std::logic_error("no job " + name);
  };
  const double embree_bvh_sah = find("embree-buildbvh", 0).sah;
  std::vector<std::string> order;
  for (BuilderKind b : kBuilders) order.emplace_back(to_string(b));
  for (const BuildJob& j : jobs)
    if (j.thread_index == 0 && j.builder.rfind(kBackendPrefix, 0) == 0) order.push_back(j.builder);
  for (const char* q : kQualities) order.push_back(std::string(kCommitPrefix) + q);
  order.emplace_back("embree-buildbvh");
  for (const auto& name : order) {
    const bool no_sah = name.rfind(kCommitPrefix, 0) == 0 || name.rfind(kBackendPrefix, 0) == 0;
    for (size_t ti = 0; ti < threads.size(); ++ti) {
      const Timed& r = find(name, ti);
      add_row(table, in, in.scene.triangle_count(), name, threads[ti], r,
              ti == 0 ? std::nullopt : std::optional<double>(find(name, 0).t.median_ms),
              no_sah ? std::nullopt : std::optional<double>(embree_bvh_sah));
    }
  }
}

// Rows of the cold first builds, each backend at each thread count, the
// samples round-robin (a fresh process each).
void add_cold_rows(Table& table, const BenchInput& in, const std::vector<int>& threads, int reps,
                   Progress& progress) {
  const ColdBuilds cold(in);
  std::vector<RoundRobinJob> timed;
  for (const auto& [backend, name] : kColdBackends)
    for (int t : threads)
      timed.push_back({reps, [&cold, backend, t](int) { return cold.build_ms(backend, t); }});
  const std::vector<TimingStats> stats = run_round_robin(timed, [&] { progress.advance(); });
  size_t i = 0;
  for (const auto& [backend, name] : kColdBackends) {
    for (size_t ti = 0; ti < threads.size(); ++ti) {
      Timed r;
      r.t = stats[i + ti];
      add_row(table, in, in.scene.triangle_count(), name, threads[ti], r,
              ti == 0 ? std::nullopt : std::optional<double>(stats[i].median_ms), std::nullopt);
    }
    i += threads.size();
  }
}

// Flatten cost of the default tree into each traversal layout (not in
// build_ms): median of `reps`, alternating the layouts.
std::string flatten_note(const BenchInput& in, const PrimInfo& prims_all, int threads, int reps) {
  const Scene& scene = in.scene;
  const size_t valid = prims_all.size();
  const BuildTree tree =
      run_with_threads(threads, [&] { return build_tree(prims_all, BuildOptions{}); });
  // As the backend flattens: after the build released the boxes (the bvh8
  // node pass then reads the few it needs from the scene). Only the refs
  // are copied: the bench holds no second set of boxes or centroids.
  PrimInfo prims;
  prims.refs = prims_all.refs;
  prims.scene_bounds = prims_all.scene_bounds;
  prims.centroid_bounds = prims_all.centroid_bounds;
  prims.invalid = prims_all.invalid;
  size_t wide_bytes = 0;
  std::vector<TimingStats> flat;
  run_with_threads(threads, [&] {
    flat = run_round_robin(
        {{reps, timed_sample([&] { (void)flatten(tree, prims, scene, kBackendArrays); })},
         {reps, timed_sample([&] {
            wide_bytes = flatten_wide<8>(tree, prims, scene, kBackendArrays).memory_bytes();
          })}});
  });
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%s: flattening the parallel tree takes %.1f ms more into the bvh2 layout "
                "and %.1f ms into bvh8 (the default; %.1f bytes/triangle) at %d threads "
                "(median of %d, not in build_ms).",
                in.label.c_str(), flat[0].median_ms, flat[1].median_ms,
                valid ? double(wide_bytes) / double(valid) : 0.0, threads, reps);
  return buf;
}

// Times one mesh into `table` and its flatten note into `report`; true when
// sweep ran fewer repetitions than the others.
bool bench_mesh(BenchReport& report, Table& table, const BenchInput& in,
                const std::vector<int>& threads, int reps, bool repeat_given,
                const std::string& backend, Progress& progress) {
  const PrimInfo prims_all = make_prim_info(in.scene);
  std::vector<BuildJob> jobs =
      list_jobs(prims_all.size(), threads.size(), reps, repeat_given, backend);
  time_jobs(jobs, threads, prims_all, in.scene, progress);
  add_rows(table, in, jobs, threads);
  add_cold_rows(table, in, threads, reps, progress);
  report.add_note(flatten_note(in, prims_all, threads.back(), reps));
  return std::any_of(jobs.begin(), jobs.end(), [&](const BuildJob& j) { return j.reps != reps; });
}

void add_table_notes(Table& table, bool sweep_fewer) {
  table.add_note(
      "build_ms: median of reps (run round-robin over the rows of a mesh); min_ms/max_ms: range. "
      "mtris_per_s = triangles / "
      "median. speedup = same builder's 1-thread median / this median.");
  table.add_note(
      "sah_cost: normalised SAH (inner 1, leaf = triangles, weighted by SA/SA(root)); "
      "sah_vs_embree_bvh = ours / rtcBuildBVH's on the same primitives (binary, "
      "leaves <= 4, same SAH constants). Embree's own BVH (commit rows) is 4/8-wide "
      "with its own leaves, so no comparable SAH cost. morton is not one of the report's "
      "builders: Morton codes, no SAH (the per-frame rebuild option of deformable scenes).");
  table.add_note(
      "bytes_per_tri: ours = binary (bvh2) nodes (32 B) + leaf triangle data as the "
      "default backend keeps it (the watertight test's vertices and the refs; the bvh8 "
      "figure is in the flatten note); "
      "embree-commit = bytes the Embree device holds after the commit (memory "
      "monitor).");
  if (sweep_fewer)
    table.add_note("sweep ran 1 repetition on meshes above " + with_commas(kSweepFewerRepsAbove) +
                   " triangles (O(n log^2 n)); pass --repeat to force a count.");
  table.add_note(
      "cold-process rows: the first build of a fresh process, as `hprt trace` and `hprt "
      "render` pay it: each repetition runs `hprt trace MESH --rays (one ray) --backend B "
      "--threads T` and takes its build_ms (bvh: prim info, build, flatten into bvh8, leaf "
      "triangles, refit index; embree: geometry + rtcCommitScene at MEDIUM), the backends "
      "alternating. The other rows repeat builds in one warm process.");
  std::string models;
  for (const auto& m : report_models())
    models += std::string(models.empty() ? "" : "; ") + with_commas(m.triangles) + " = " + m.name +
              " (ours: ../shared/data/meshes/" + m.real_mesh + ", " + m.real_notes + ")";
  table.add_note("Report Table 1 models: " + models + ".");
  table.add_note(
      "The report's own Table 1 (High Performance Ray Tracing, Chen, Sun, Xu, 2012; its "
      "32-core machine, seconds): Crytek Sponza 132,267 triangles 1.575 sequential, 0.355 "
      "parallel (4.43x); Chinese Dragon 871,306: 11.753, 2.399 (4.90x); Happy Buddha "
      "1,087,474: 15.116, 3.480 (4.34x).");
}

}  // namespace

BenchReport run_build_bench(const BuildBenchConfig& config) {
  const BenchOptions& o = config.common;
  check_bench_options(o);
  const int reps = repetitions(o, 5, 1);
  const std::vector<int> threads = thread_counts(o);
  const std::vector<BenchInput> inputs = load_inputs(config);

  BenchReport report("build", "BVH build time (report Table 1, Embree beside)", o);
  report.set_param("threads", threads);
  report.set_param("repetitions", reps);
  report.set_param("timed_call",
                   "ours: make_prim_info + build_tree; embree-commit: backend build() "
                   "(geometry + rtcCommitScene); embree-buildbvh: rtcBuildBVH");
  Table& table =
      report.add_table("table", "Build time per builder and thread count", make_build_table());

  Progress progress(
      "bench build",
      count_steps(inputs, threads.size(), reps, o.repeat.has_value(), !config.backend.empty()),
      o.progress);
  if (!config.backend.empty())
    table.add_note(std::string(kBackendPrefix) + config.backend +
                   ": that backend's build() from the scene to a structure it traces (for bvh: "
                   "prim info, build, flatten into the default layout).");
  bool sweep_fewer = false;
  for (const auto& in : inputs)
    if (bench_mesh(report, table, in, threads, reps, o.repeat.has_value(), config.backend,
                   progress))
      sweep_fewer = true;
  progress.finish();

  for (const auto& in : inputs) report.add_note(in.label + ": " + in.source);
  add_table_notes(table, sweep_fewer);
  return report;
}

}  // namespace hprt::bench
