// Frontier benchmark. Error is measured against the exact arbiter
// (validators/arbiter.h) over every triangle of the scene (brute force), so
// no backend is trusted: a configuration's hit is wrong when
// closest_hit_right() (validators/ray_diff.h, the rule `hprt validate rays`
// applies) says so. Hard-case sets: vertex and edge probes from inside the
// closed mesh, grazing and axis-parallel rays, on the mesh and on a copy
// scaled to radius 10 and moved to (1e6, -1e6, 1e6) (float spacing 1/16).
// PSNR: a small Whitted render against the reference configuration's render
// (bvh sweep + watertight, whose rays the arbiter checks like all others).
// The ray sets and their judging: bench_frontier_rays.h.
#include "bench/frontier/bench_frontier.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "bench/bench_inputs.h"
#include "bench/bench_timing.h"
#include "bench/frontier/bench_frontier_plot.h"
#include "bench/frontier/bench_frontier_rays.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/scene/scene_reader.h"
#include "meshgen/mesh_generators.h"
#include "render/progress.h"
#include "render/whitted.h"
#include "validators/image_diff.h"
#include "validators/ray_sets.h"

namespace hprt::bench {
namespace {

struct Config {
  std::string name;
  BackendOptions options;
  bool is_default = false;
  bool is_reference = false;
};

// hprt's configurations, Embree's two, and `backend` (a --backend spec) when given.
std::vector<Config> make_configs(int threads, const std::string& backend) {
  std::vector<Config> out;
  auto bvh = [&](BuilderKind b, int bins, int leaf, TriangleTestKind t,
                 BvhLayout layout = BvhLayout::kBvh8) {
    Config c;
    c.options.backend = "bvh";
    c.options.threads = threads;
    c.options.build.builder = b;
    c.options.build.bins = bins;
    c.options.build.max_leaf_size = leaf;
    c.options.triangle_test = t;
    c.options.layout = layout;
    c.name = "bvh/" + std::string(to_string(b));
    if (b == BuilderKind::kBinned || b == BuilderKind::kParallel)
      c.name += "/bins" + std::to_string(bins);
    c.name += "/leaf" + std::to_string(leaf) + "/" + std::string(to_string(t));
    if (layout != BvhLayout::kBvh8) c.name += "/" + std::string(to_string(layout));
    const BackendOptions defaults;
    c.is_default = b == defaults.build.builder && bins == defaults.build.bins &&
                   leaf == defaults.build.max_leaf_size && t == defaults.triangle_test &&
                   layout == defaults.layout;
    return c;
  };
  const auto wt = TriangleTestKind::kWatertight, mt = TriangleTestKind::kMoller;
  Config ref = bvh(BuilderKind::kSweep, 32, 4, wt);
  ref.is_reference = true;
  out.push_back(ref);
  out.push_back(bvh(BuilderKind::kSweep, 32, 4, mt));
  out.push_back(bvh(BuilderKind::kPresorted, 32, 4, wt));
  for (int bins : {4, 8, 16, 32, 64}) out.push_back(bvh(BuilderKind::kBinned, bins, 4, wt));
  for (auto t : {wt, mt})
    for (int leaf : {1, 2, 4, 8}) out.push_back(bvh(BuilderKind::kParallel, 32, leaf, t));
  for (BvhLayout layout : {BvhLayout::kBvh2, BvhLayout::kBvh4})
    out.push_back(bvh(BuilderKind::kParallel, 32, 4, wt, layout));
  for (bool robust : {false, true}) {
    Config c;
    c.options.backend = "embree";
    c.options.threads = threads;
    c.options.embree_quality = "medium";
    c.options.embree_robust = robust;
    c.name = std::string("embree/medium/robust-") + (robust ? "on" : "off");
    out.push_back(c);
  }
  if (!backend.empty()) {
    Config c;
    c.options.backend = backend;
    c.options.threads = threads;
    c.name = backend;
    out.push_back(c);
  }
  return out;
}

Image to_image(const Framebuffer& fb) {
  Image img;
  img.width = fb.width();
  img.height = fb.height();
  img.channels = 3;
  img.pixels.reserve(size_t(img.width) * size_t(img.height) * 3);
  for (const Vec3f& p : fb.pixels())
    for (float v : {p.x, p.y, p.z}) img.pixels.push_back(std::clamp(v, 0.0f, 1.0f));
  return img;
}

// Run sizes from the options (quick or full where not given).
struct Sizes {
  int reps = 0;
  int threads = 0;
  size_t hard_rays = 0;   // per hard-case set
  size_t trace_rays = 0;  // primary rays timed, and as many random ones
  int img_w = 0, img_h = 0;
};

Sizes make_sizes(const FrontierBenchConfig& config) {
  const BenchOptions& o = config.common;
  Sizes sz;
  sz.reps = repetitions(o, 5, 1);
  sz.threads = resolve_threads(o.threads);
  check_ray_count("hard_rays", config.hard_rays);
  check_ray_count("trace_rays", config.trace_rays);
  sz.hard_rays = config.hard_rays ? config.hard_rays : (o.quick ? 200 : 2000);
  sz.trace_rays = config.trace_rays ? config.trace_rays : (o.quick ? 10'000 : 250'000);
  sz.img_w = o.quick ? 96 : 320;
  sz.img_h = o.quick ? 72 : 240;
  return sz;
}

// The given mesh, or a generated sphere (closed, so the probes apply).
BenchInput load_input(const FrontierBenchConfig& config) {
  if (!config.mesh.empty()) return file_input(config.mesh);
  BenchInput in;
  const size_t tris = config.common.quick ? 5'000 : 80'000;
  in.scene.add_mesh(generate_sphere(tris));
  in.label = "sphere";
  in.source = "generated sphere of " + with_commas(in.scene.triangle_count()) +
              " triangles (closed, so vertex/edge probes apply)";
  Camera lens;
  in.scene.camera = framing_camera(in.scene.bounds(), lens);
  in.scene.lights.push_back(head_light(in.scene.camera));
  return in;
}

Table make_table() {
  return Table({{"config", 0},        {"backend", 0},      {"builder", 0},      {"bins", 0},
                {"leaf_size", 0},     {"isect", 0},        {"robust", 0},       {"build_ms", 1},
                {"build_min_ms", 1},  {"build_max_ms", 1}, {"sah_cost", 2},     {"sah_vs_sweep", 3},
                {"trace_ms", 1},      {"trace_min_ms", 1}, {"trace_max_ms", 1}, {"mrays_per_s", 2},
                {"hard_rays", 0},     {"wrong_rays", 0},   {"wrong_pct", 3},    {"wrong_probe", 0},
                {"wrong_grazing", 0}, {"wrong_axis", 0},   {"wrong_offset", 0}, {"psnr_db", 2},
                {"pareto", 0},        {"default", 0}});
}

// The configuration's own columns: backend, builder, bins, leaf size, test.
void set_config_columns(Table::RowBuilder& row, const Config& c) {
  row.set("config", c.name).set("backend", c.options.backend);
  if (c.options.backend == "bvh") {
    row.set("builder", std::string(to_string(c.options.build.builder)))
        .set("leaf_size", c.options.build.max_leaf_size)
        .set("isect", std::string(to_string(c.options.triangle_test)));
    if (c.options.build.builder == BuilderKind::kBinned ||
        c.options.build.builder == BuilderKind::kParallel)
      row.set("bins", c.options.build.bins);
  } else {
    row.set("builder", "embree-" + c.options.embree_quality)
        .set("isect", "embree")
        .set("robust", c.options.embree_robust ? "on" : "off");
  }
}

// Wrong hard-case rays of `c` (`near` built on the mesh, a copy built here on
// `far`), per group; returns the total.
size_t set_wrong_columns(Table::RowBuilder& row, const FrontierRays& rays, const Config& c,
                         const Intersector& near, const Scene& far) {
  size_t wrong = 0, probe = 0, grazing = 0, axis = 0, offset = 0;
  std::unique_ptr<Intersector> bfar = make_intersector(c.options.backend, c.options);
  bfar->build(far);
  for (const HardSet& s : rays.hard) {
    const size_t w = count_wrong(s, s.scene == &far ? *bfar : near);
    wrong += w;
    if (s.group == "probe") probe += w;
    if (s.group == "grazing") grazing += w;
    if (s.group == "axis") axis += w;
    if (s.group == "offset") offset += w;
  }
  const size_t total = rays.hard_total;
  row.set("hard_rays", total)
      .set("wrong_rays", wrong)
      .set("wrong_pct", total ? 100.0 * double(wrong) / double(total) : 0.0)
      .set("wrong_probe", probe)
      .set("wrong_grazing", grazing)
      .set("wrong_axis", axis)
      .set("wrong_offset", offset);
  return wrong;
}

// What later configurations compare against, and every built backend, kept
// for the interleaved trace timing.
struct Measured {
  double sweep_sah = 0.0;  // the reference's
  std::optional<Image> reference_image;
  std::vector<FrontierPoint> points;
  std::vector<std::unique_ptr<Intersector>> built;
};

// PSNR of `b`'s small Whitted render against the reference configuration's
// (the first measured, which stores its image).
double psnr_db(const Scene& scene, const Intersector& b, const Config& c, const Sizes& sz,
               const std::string& reference_name, std::optional<Image>& reference_image) {
  Camera cam = scene.camera;
  cam.width = sz.img_w;
  cam.height = sz.img_h;
  const Image img = to_image(render_whitted(scene, cam, b));
  if (c.is_reference) reference_image = img;
  const ImageDiff d =
      diff_images(img, *reference_image, kDefaultDiffThreshold, c.name, reference_name);
  return d.psnr_db;
}

// One configuration's row but the trace columns: build timing, tree quality,
// wrong rays, PSNR.
void measure_config(Table& table, const Config& c, const Scene& scene, const Scene& far,
                    const FrontierRays& rays, const Sizes& sz, const std::string& reference_name,
                    Measured& measured) {
  FrontierPoint p;
  p.name = c.name;
  p.is_default = c.is_default;
  auto row = table.new_row();
  set_config_columns(row, c);
  run_with_threads(sz.threads, [&] {
    std::unique_ptr<Intersector> b;
    const TimingStats build = time_repeated(
        sz.reps,
        [&] {
          b.reset();
          b = make_intersector(c.options.backend, c.options);
        },
        [&] { b->build(scene); });
    const BuildInfo info = b->info();
    row.set("build_ms", build.median_ms)
        .set("build_min_ms", build.min_ms)
        .set("build_max_ms", build.max_ms);
    if (info.has_tree_stats) {
      if (c.is_reference) measured.sweep_sah = info.stats.sah_cost;
      row.set("sah_cost", info.stats.sah_cost);
      if (measured.sweep_sah > 0) row.set("sah_vs_sweep", info.stats.sah_cost / measured.sweep_sah);
    }
    p.wrong_rays = double(set_wrong_columns(row, rays, c, *b, far));
    row.set("psnr_db", psnr_db(scene, *b, c, sz, reference_name, measured.reference_image));
    measured.built.push_back(std::move(b));
  });
  row.set("default", c.is_default ? "yes" : "no");
  measured.points.push_back(p);
}

// Trace timing round-robin over the configurations, so a change in the load
// of a shared machine spreads over all rows instead of skewing a few.
void time_traces(Table& table, Measured& measured, const std::vector<Ray>& trace_rays,
                 const Sizes& sz) {
  std::vector<TimingStats> traces;
  run_with_threads(sz.threads, [&] {
    std::vector<Hit> hits(trace_rays.size());
    std::vector<RoundRobinJob> jobs;
    for (const auto& b : measured.built)
      jobs.push_back({sz.reps, timed_sample([&] { b->intersect(trace_rays, hits); })});
    traces = run_round_robin(jobs);
  });
  measured.built.clear();
  for (size_t i = 0; i < traces.size(); ++i) {
    const TimingStats& trace = traces[i];
    measured.points[i].mrays_per_s =
        trace.median_ms > 0 ? double(trace_rays.size()) / (trace.median_ms * 1e3) : 0.0;
    table.edit_row(i)
        .set("trace_ms", trace.median_ms)
        .set("trace_min_ms", trace.min_ms)
        .set("trace_max_ms", trace.max_ms)
        .set("mrays_per_s", measured.points[i].mrays_per_s);
  }
}

void add_notes(BenchReport& report, Table& table, const Sizes& sz,
               const std::vector<std::string>& skipped) {
  table.add_note(
      "build_ms: backend build() (bvh: prim info + builder + flatten; embree: "
      "geometry + rtcCommitScene), median of reps at " +
      std::to_string(sz.threads) +
      " threads. trace: closest hit of the primary + random "
      "rays, median of reps taken round-robin over the configurations. sah_vs_sweep = SAH cost / "
      "sweep's (the reference).");
  table.add_note(
      "wrong_rays: hard-case rays whose hit the exact arbiter (brute force over every "
      "triangle) rejects, by the rule of `hprt validate rays` (t within 1e-5 relative, "
      "edge tolerance 2^-19 of the coordinate scale; a miss is wrong when a triangle is "
      "surely hit). Sets: vertex-probe, edge-probe (group probe), grazing, axis, each "
      "again on the mesh scaled to radius 10 at (1e6, -1e6, 1e6) (group offset).");
  table.add_note("psnr_db: " + std::to_string(sz.img_w) + "x" + std::to_string(sz.img_h) +
                 " Whitted render (pixels clamped to [0,1]) against the reference configuration "
                 "bvh/sweep/leaf4/watertight (inf = identical). pareto: not dominated in (Mrays/s "
                 "higher, wrong_rays lower). default: the configuration hprt uses unless told.");
  for (const auto& s : skipped) report.add_note("skipped hard-case set " + s);
}

}  // namespace

BenchReport run_frontier_bench(const FrontierBenchConfig& config) {
  const BenchOptions& o = config.common;
  check_bench_options(o);
  const Sizes sz = make_sizes(config);
  const BenchInput in = load_input(config);
  if (in.scene.triangle_count() == 0) throw InputError(in.source, "mesh has no triangles");
  const Scene& scene = in.scene;
  const Scene far = offset_scene(scene);

  BenchReport report("frontier", "Speed against error (Pareto front)", o);
  report.set_param("threads", sz.threads);
  report.set_param("repetitions", sz.reps);
  report.set_param("mesh", in.label + ": " + in.source);
  report.set_param("hard_rays_per_set", sz.hard_rays);
  report.set_param("trace_rays", std::to_string(sz.trace_rays) + " primary + " +
                                     std::to_string(sz.trace_rays) + " random, closest hit");
  report.set_param("image", std::to_string(sz.img_w) + "x" + std::to_string(sz.img_h));

  const std::vector<Config> configs = make_configs(sz.threads, config.backend);
  Progress progress("bench frontier", configs.size() + 1, o.progress);
  const FrontierRays rays = make_frontier_rays(scene, far, sz.threads, sz.hard_rays, sz.trace_rays);
  progress.advance();

  Table& table =
      report.add_table("table", "Configurations: speed, tree quality and error", make_table());
  Measured measured;
  for (const Config& c : configs) {
    measure_config(table, c, scene, far, rays, sz, configs.front().name, measured);
    progress.advance();
  }
  progress.finish();

  time_traces(table, measured, rays.trace, sz);
  mark_pareto(measured.points);
  for (size_t i = 0; i < measured.points.size(); ++i)
    table.edit_row(i).set("pareto", measured.points[i].pareto ? "yes" : "no");
  add_notes(report, table, sz, rays.skipped);

  if (!o.out_dir.empty()) {
    const PlotResult plot = write_frontier_plot(measured.points, o.out_dir, in.label);
    if (plot.written)
      report.add_file(plot.path);
    else
      report.add_note("plot not written: " + plot.message);
  }
  return report;
}

}  // namespace hprt::bench
