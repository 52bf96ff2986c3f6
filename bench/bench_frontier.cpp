// Frontier benchmark. Error is measured against the exact arbiter
// (validators/arbiter.h) over every triangle of the scene (brute force), so
// no backend is trusted: a configuration's hit is wrong when
// closest_hit_right() (validators/ray_diff.h, the rule `hprt validate rays`
// applies) says so. Hard-case sets: vertex and edge probes from inside the
// closed mesh, grazing and axis-parallel rays, on the mesh and on a copy
// scaled to radius 10 and moved to (1e6, -1e6, 1e6) (float spacing 1/16).
// PSNR: a small Whitted render against the reference configuration's render
// (bvh sweep + watertight, whose rays the arbiter checks like all others).
#include "bench/bench_frontier.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "backends/intersector.h"
#include "bench/bench_frontier_plot.h"
#include "bench/bench_inputs.h"
#include "bench/bench_timing.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/scene_reader.h"
#include "meshgen/mesh_generators.h"
#include "render/progress.h"
#include "render/whitted.h"
#include "validators/arbiter.h"
#include "validators/image_diff.h"
#include "validators/ray_diff.h"
#include "validators/ray_sets.h"

namespace hprt::bench {
namespace {

struct Config {
  std::string name;
  BackendOptions options;
  bool is_default = false;
  bool is_reference = false;
};

std::vector<Config> make_configs(int threads) {
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
  return out;
}

// One hard-case ray set with its exact answers.
struct HardSet {
  std::string label;  // "vertex-probe", "grazing@1e6", ...
  std::string group;  // column it counts in: probe, grazing, axis, offset
  const Scene* scene = nullptr;
  std::vector<Ray> rays;
  std::vector<ArbiterAnswer> answers;
};

Scene offset_scene(const Scene& base) {
  Scene s;
  const AABB b = base.bounds();
  const Vec3f c = (b.min + b.max) * 0.5f;
  const Vec3f e = b.max - b.min;
  const float radius = 0.5f * std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
  const float scale = radius > 0 ? 10.0f / radius : 1.0f;
  const Vec3d offset(1e6, -1e6, 1e6);
  for (const auto& m0 : base.meshes) {
    TriangleMesh m = m0;
    for (Vec3f& p : m.positions) p = Vec3f((Vec3d(p) - Vec3d(c)) * double(scale) + offset);
    m.normals.clear();
    s.add_mesh(std::move(m));
  }
  s.camera = base.camera;
  s.lights = base.lights;
  return s;
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

// A hit on a triangle outside the brute-force candidates (the exact line
// misses it, e.g. by 1e-9 beside a shared edge) is judged with that triangle
// added, as arbitrate_dispute() in ray_diff.cpp does: within the edge
// tolerance it is right.
size_t count_wrong(const HardSet& set, const Intersector& b, const RayDiffOptions& opts) {
  std::vector<Hit> hits(set.rays.size());
  b.intersect(set.rays, hits);
  size_t wrong = 0;
  for (size_t i = 0; i < set.rays.size(); ++i) {
    const ArbiterAnswer& ans = set.answers[i];
    const Hit& h = hits[i];
    bool right;
    if (h.hit()) {
      ArbiterAnswer with_hit = ans;
      add_candidate(*set.scene, set.rays[i], PrimRef{h.geom_id, h.prim_id}, with_hit);
      right = closest_hit_right(with_hit, set.rays[i], h, opts);
    } else {
      right = closest_hit_right(ans, set.rays[i], h, opts);
    }
    if (!right) ++wrong;
  }
  return wrong;
}

}  // namespace

BenchReport run_frontier_bench(const FrontierBenchConfig& config) {
  const BenchOptions& o = config.common;
  check_bench_options(o);
  const int reps = repetitions(o, 5, 1);
  const int threads = resolve_threads(o.threads);
  const size_t n_hard = config.hard_rays ? config.hard_rays : (o.quick ? 200 : 2000);
  const size_t n_trace = config.trace_rays ? config.trace_rays : (o.quick ? 10'000 : 250'000);
  const int img_w = o.quick ? 96 : 320, img_h = o.quick ? 72 : 240;

  BenchInput in;
  if (config.mesh.empty()) {
    const size_t tris = o.quick ? 5'000 : 80'000;
    in.scene.add_mesh(generate_sphere(tris));
    in.label = "sphere";
    in.source = "generated sphere of " + with_commas(in.scene.triangle_count()) +
                " triangles (closed, so vertex/edge probes apply)";
    Camera lens;
    in.scene.camera = framing_camera(in.scene.bounds(), lens);
    in.scene.lights.push_back(head_light(in.scene.camera));
  } else {
    in = file_input(config.mesh);
  }
  if (in.scene.triangle_count() == 0) throw InputError(in.source, "mesh has no triangles");
  const Scene& scene = in.scene;
  const Scene far = offset_scene(scene);

  BenchReport report("frontier", "Speed against error (Pareto front)", o);
  report.set_param("threads", threads);
  report.set_param("repetitions", reps);
  report.set_param("mesh", in.label + ": " + in.source);
  report.set_param("hard_rays_per_set", n_hard);
  report.set_param("trace_rays", std::to_string(n_trace) + " primary + " + std::to_string(n_trace) +
                                     " random, closest hit");
  report.set_param("image", std::to_string(img_w) + "x" + std::to_string(img_h));

  const std::vector<Config> configs = make_configs(threads);
  Progress progress("bench frontier", configs.size() + 1, o.progress);
  RayDiffOptions diff_opts;

  // Ray sets (generated through the embree backend where a kind needs hits)
  // and the exact answers, once for all configurations.
  std::vector<HardSet> sets;
  std::vector<Ray> trace_rays;
  std::vector<std::string> skipped;
  run_with_threads(threads, [&] {
    BackendOptions gen_options;
    gen_options.backend = "embree";
    gen_options.threads = threads;
    auto gen = make_intersector("embree", gen_options);
    gen->build(scene);
    trace_rays = make_rays(scene, RayKind::kPrimary, n_trace, 1, gen.get());
    const std::vector<Ray> random = make_rays(scene, RayKind::kRandom, n_trace, 2, gen.get());
    trace_rays.insert(trace_rays.end(), random.begin(), random.end());
    const std::pair<RayKind, const char*> kinds[] = {{RayKind::kVertexProbe, "probe"},
                                                     {RayKind::kEdgeProbe, "probe"},
                                                     {RayKind::kGrazing, "grazing"},
                                                     {RayKind::kAxis, "axis"}};
    for (const Scene* s : {&scene, &far}) {
      for (const auto& [kind, group] : kinds) {
        HardSet h;
        h.scene = s;
        h.label = std::string(to_string(kind)) + (s == &far ? "@1e6" : "");
        h.group = s == &far ? "offset" : group;
        try {
          h.rays = make_rays(*s, kind, n_hard, 3, nullptr);
        } catch (const InputError& e) {
          skipped.push_back(h.label + " (" + e.what() + ")");
          continue;
        }
        h.answers.resize(h.rays.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, h.rays.size(), 8),
                          [&](const tbb::blocked_range<size_t>& r) {
                            for (size_t i = r.begin(); i != r.end(); ++i)
                              h.answers[i] = arbitrate_scene(*s, h.rays[i], diff_opts);
                          });
        sets.push_back(std::move(h));
      }
    }
  });
  progress.advance();
  size_t hard_total = 0;
  for (const auto& s : sets) hard_total += s.rays.size();

  Table& table = report.add_table(
      "table", "Configurations: speed, tree quality and error",
      Table({{"config", 0},        {"backend", 0},      {"builder", 0},      {"bins", 0},
             {"leaf_size", 0},     {"isect", 0},        {"robust", 0},       {"build_ms", 1},
             {"build_min_ms", 1},  {"build_max_ms", 1}, {"sah_cost", 2},     {"sah_vs_sweep", 3},
             {"trace_ms", 1},      {"trace_min_ms", 1}, {"trace_max_ms", 1}, {"mrays_per_s", 2},
             {"hard_rays", 0},     {"wrong_rays", 0},   {"wrong_pct", 3},    {"wrong_probe", 0},
             {"wrong_grazing", 0}, {"wrong_axis", 0},   {"wrong_offset", 0}, {"psnr_db", 2},
             {"pareto", 0},        {"default", 0}}));

  std::optional<Image> reference_image;
  double sweep_sah = 0.0;
  std::vector<FrontierPoint> points;
  std::vector<std::unique_ptr<Intersector>> built;  // kept for the interleaved trace timing
  for (const Config& c : configs) {
    const bool is_bvh = c.options.backend == "bvh";
    FrontierPoint p;
    p.name = c.name;
    p.is_default = c.is_default;
    auto row = table.new_row();
    row.set("config", c.name).set("backend", c.options.backend);
    if (is_bvh) {
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
    run_with_threads(threads, [&] {
      std::unique_ptr<Intersector> b;
      const TimingStats build = time_repeated(
          reps,
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
        if (c.is_reference) sweep_sah = info.stats.sah_cost;
        row.set("sah_cost", info.stats.sah_cost);
        if (sweep_sah > 0) row.set("sah_vs_sweep", info.stats.sah_cost / sweep_sah);
      }
      size_t wrong = 0, probe = 0, grazing = 0, axis = 0, offset = 0;
      std::unique_ptr<Intersector> bfar = make_intersector(c.options.backend, c.options);
      bfar->build(far);
      for (const HardSet& s : sets) {
        const size_t w = count_wrong(s, s.scene == &far ? *bfar : *b, diff_opts);
        wrong += w;
        if (s.group == "probe") probe += w;
        if (s.group == "grazing") grazing += w;
        if (s.group == "axis") axis += w;
        if (s.group == "offset") offset += w;
      }
      p.wrong_rays = double(wrong);
      row.set("hard_rays", hard_total)
          .set("wrong_rays", wrong)
          .set("wrong_pct", hard_total ? 100.0 * double(wrong) / double(hard_total) : 0.0)
          .set("wrong_probe", probe)
          .set("wrong_grazing", grazing)
          .set("wrong_axis", axis)
          .set("wrong_offset", offset);

      Camera cam = scene.camera;
      cam.width = img_w;
      cam.height = img_h;
      const Image img = to_image(render_whitted(scene, cam, *b));
      if (c.is_reference) reference_image = img;
      const ImageDiff d =
          diff_images(img, *reference_image, kDefaultDiffThreshold, c.name, configs.front().name);
      row.set("psnr_db", d.psnr_db);
      built.push_back(std::move(b));
    });
    row.set("default", c.is_default ? "yes" : "no");
    points.push_back(p);
    progress.advance();
  }
  progress.finish();

  // Trace timing round-robin over the configurations (repetition r of every
  // configuration before repetition r+1 of any), so a change in the load of
  // a shared machine spreads over all rows instead of skewing a few.
  std::vector<std::vector<double>> samples(configs.size());
  run_with_threads(threads, [&] {
    std::vector<Hit> hits(trace_rays.size());
    for (int r = 0; r < reps; ++r)
      for (size_t i = 0; i < configs.size(); ++i)
        samples[i].push_back(time_ms([&] { built[i]->intersect(trace_rays, hits); }));
  });
  built.clear();
  for (size_t i = 0; i < configs.size(); ++i) {
    const TimingStats trace = summarize_ms(samples[i]);
    points[i].mrays_per_s =
        trace.median_ms > 0 ? double(trace_rays.size()) / (trace.median_ms * 1e3) : 0.0;
    table.edit_row(i)
        .set("trace_ms", trace.median_ms)
        .set("trace_min_ms", trace.min_ms)
        .set("trace_max_ms", trace.max_ms)
        .set("mrays_per_s", points[i].mrays_per_s);
  }

  mark_pareto(points);
  for (size_t i = 0; i < points.size(); ++i)
    table.edit_row(i).set("pareto", points[i].pareto ? "yes" : "no");

  table.add_note(
      "build_ms: backend build() (bvh: prim info + builder + flatten; embree: "
      "geometry + rtcCommitScene), median of reps at " +
      std::to_string(threads) +
      " threads. trace: closest hit of the primary + random "
      "rays, median of reps taken round-robin over the configurations. sah_vs_sweep = SAH cost / "
      "sweep's (the reference).");
  table.add_note(
      "wrong_rays: hard-case rays whose hit the exact arbiter (brute force over every "
      "triangle) rejects, by the rule of `hprt validate rays` (t within 1e-5 relative, "
      "edge tolerance 2^-19 of the coordinate scale; a miss is wrong when a triangle is "
      "surely hit). Sets: vertex-probe, edge-probe (group probe), grazing, axis, each "
      "again on the mesh scaled to radius 10 at (1e6, -1e6, 1e6) (group offset).");
  table.add_note("psnr_db: " + std::to_string(img_w) + "x" + std::to_string(img_h) +
                 " Whitted render (pixels clamped to [0,1]) against the reference configuration "
                 "bvh/sweep/leaf4/watertight (inf = identical). pareto: not dominated in (Mrays/s "
                 "higher, wrong_rays lower). default: the configuration hprt uses unless told.");
  for (const auto& s : skipped) report.add_note("skipped hard-case set " + s);

  if (!o.out_dir.empty()) {
    const PlotResult plot = write_frontier_plot(points, o.out_dir, in.label);
    if (plot.written)
      report.add_file(plot.path);
    else
      report.add_note("plot not written: " + plot.message);
  }
  return report;
}

}  // namespace hprt::bench
