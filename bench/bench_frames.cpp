// The deformable-scene benchmark: for each animation case and each backend
// configuration, a fresh copy of the scene is animated (SceneAnimator, frame
// 0 built untimed in the table's update columns), then per frame: deform
// (timed apart), update() (the BVH/Embree update), render (Whitted, the
// scene's camera). Medians, means and min-max over the frames; ratios of
// means (an adaptive strategy's occasional rebuild frames count in full)
// against Embree's dynamic refit (update), the fastest Embree row (whole
// frame), and the fastest Embree row of matching numerics: our watertight
// test against Embree's robust mode, Möller–Trumbore against its default.
#include "bench/bench_frames.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "anim/scene_animator.h"
#include "backends/intersector.h"
#include "bench/bench_inputs.h"
#include "bench/bench_timing.h"
#include "core/error.h"
#include "core/parallel.h"
#include "render/animation_loop.h"
#include "render/progress.h"
#include "render/whitted.h"

namespace hprt::bench {
namespace {

struct FrameConfig {
  const char* label;    // table row
  const char* backend;  // bvh | embree | a --backend spec (plugin:PATH.so)
  UpdateStrategy update;
  const char* quality;                                    // embree build quality
  TriangleTestKind test = TriangleTestKind::kWatertight;  // bvh
  bool robust = false;                                    // embree
  BuilderKind builder = BuilderKind::kParallel;           // bvh
  // Watertight bvh and robust Embree, or Möller–Trumbore and Embree's default.
  bool careful() const {
    return std::string(backend) == "bvh" ? test == TriangleTestKind::kWatertight : robust;
  }
};

// The first row runs with the default options (BackendOptions{}).
constexpr FrameConfig kConfigs[] = {
    {"bvh auto (default)", "bvh", UpdateStrategy::kAuto, "medium"},
    {"bvh rebuild", "bvh", UpdateStrategy::kRebuild, "medium"},
    {"bvh refit", "bvh", UpdateStrategy::kRefit, "medium"},
    {"bvh adaptive", "bvh", UpdateStrategy::kAdaptive, "medium"},
    {"bvh adaptive mt", "bvh", UpdateStrategy::kAdaptive, "medium", TriangleTestKind::kMoller},
    {"bvh rebuild morton", "bvh", UpdateStrategy::kRebuild, "medium", TriangleTestKind::kWatertight,
     false, BuilderKind::kMorton},
    {"bvh adaptive morton", "bvh", UpdateStrategy::kAdaptive, "medium",
     TriangleTestKind::kWatertight, false, BuilderKind::kMorton},
    {"bvh adaptive morton mt", "bvh", UpdateStrategy::kAdaptive, "medium",
     TriangleTestKind::kMoller, false, BuilderKind::kMorton},
    {"embree dynamic refit", "embree", UpdateStrategy::kAdaptive, "refit"},
    {"embree dynamic low", "embree", UpdateStrategy::kAdaptive, "low"},
    {"embree dynamic refit robust", "embree", UpdateStrategy::kAdaptive, "refit",
     TriangleTestKind::kWatertight, true},
    {"embree dynamic low robust", "embree", UpdateStrategy::kAdaptive, "low",
     TriangleTestKind::kWatertight, true},
};
constexpr size_t kEmbreeRefitRow = 8;
static_assert(std::string_view(kConfigs[kEmbreeRefitRow].label) == "embree dynamic refit");

struct AnimCase {
  std::string name;  // "wave", "explode" or the scene's own
  Scene scene;       // with scene.animation set
  int frames = 0;    // timed frames: 1 .. frames
};

struct CaseResult {
  double build_ms = 0.0;  // frame 0
  TimingStats deform, update, render, frame;
  int rebuilds = 0;
  std::string updates;                     // a letter per timed frame (update_letter)
  double sah_first = 0.0, sah_last = 0.0;  // after frame 1 and the last frame
  double mrays_per_s = 0.0;                // over all timed frames' renders
};

// Wave and explode scaled to the scene: amplitudes relative to the bounding
// box diagonal (wave 1%, explode 25% per second of animation).
std::vector<AnimCase> default_cases(const Scene& scene, int frames) {
  const float diag = length(scene.bounds().diagonal());
  std::vector<AnimCase> out;
  for (const char* kind : {"wave", "explode"}) {
    AnimCase c;
    c.name = kind;
    c.scene = scene;
    c.frames = frames;
    c.scene.animation = Animation{};
    c.scene.animation.frames = frames + 1;
    c.scene.animation.fps = 24.0f;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      DeformerSpec d;
      d.mesh = int(m);
      d.kind = kind;
      d.speed = 1.0f;
      if (c.name == "wave") {
        d.amplitude = 0.01f * diag;
        d.wavelength = 0.25f * diag;
      } else {
        d.amplitude = 0.25f * diag;
      }
      c.scene.animation.deformers.push_back(d);
    }
    out.push_back(std::move(c));
  }
  return out;
}

// What a frame's update did: r refit, m Morton rebuild, s rebuild with an
// SAH builder, b a rebuild of a backend that does not name its builder.
char update_letter(const BuildInfo& info) {
  if (!info.rebuilt) return 'r';
  if (info.rebuilt_with.empty()) return 'b';
  return info.rebuilt_with == "morton" ? 'm' : 's';
}

CaseResult run_config(const AnimCase& ac, const FrameConfig& fc, int threads, float factor,
                      Progress& progress) {
  CaseResult res;
  Scene scene = ac.scene;
  std::vector<double> deform, update, render, frame;
  uint64_t rays = 0;
  double render_total_ms = 0.0;
  run_with_threads(threads, [&] {
    const SceneAnimator animator(scene);
    // Copies and unwelding may drop Embree's spare vertex; without it the
    // backend would copy the vertices every frame, which is not Embree's cost.
    for (TriangleMesh& m : scene.meshes) m.pad_for_embree();
    BackendOptions o;
    o.threads = threads;
    o.update = fc.update;
    o.embree_quality = fc.quality;
    o.triangle_test = fc.test;
    o.build.builder = fc.builder;
    o.embree_robust = fc.robust;
    o.adaptive_factor = factor;
    std::unique_ptr<Intersector> isect = make_intersector(fc.backend, o);
    // Frame 0 is built, not rendered or counted; frames 1 .. ac.frames are timed.
    const auto render_one = [&](int, RenderStats& stats) {
      return time_ms([&] { render_whitted(scene, scene.camera, *isect, &stats); });
    };
    const auto record = [&](const AnimationFrame& f) {
      if (f.frame == 0) {
        res.build_ms = f.update_ms;
        return;
      }
      deform.push_back(f.animate_ms);
      res.rebuilds += f.info.rebuilt ? 1 : 0;
      res.updates += update_letter(f.info);
      if (f.info.has_tree_stats) {
        if (f.frame == 1) res.sah_first = f.info.stats.sah_cost;
        res.sah_last = f.info.stats.sah_cost;
      }
      update.push_back(f.update_ms);
      render.push_back(f.render_ms);
      frame.push_back(f.update_ms + f.render_ms);
      rays += f.stats.rays();
      render_total_ms += f.render_ms;
      progress.advance();
    };
    run_animation(scene, animator, *isect, {0, ac.frames + 1, false}, render_one, record);
  });
  res.deform = summarize_ms(deform);
  res.update = summarize_ms(update);
  res.render = summarize_ms(render);
  res.frame = summarize_ms(frame);
  res.mrays_per_s = render_total_ms > 0.0 ? double(rays) / (render_total_ms * 1e3) : 0.0;
  return res;
}

Table make_table() {
  return Table({{"case", 0},
                {"config", 0},
                {"default", 0},
                {"triangles", 0},
                {"threads", 0},
                {"frames", 0},
                {"build_ms", 1},
                {"update_ms", 2},
                {"update_min_ms", 2},
                {"update_max_ms", 2},
                {"update_mean_ms", 2},
                {"render_ms", 1},
                {"render_min_ms", 1},
                {"render_max_ms", 1},
                {"frame_ms", 1},
                {"frame_min_ms", 1},
                {"frame_max_ms", 1},
                {"frame_mean_ms", 1},
                {"deform_ms", 2},
                {"rebuilds", 0},
                {"updates", 0},
                {"sah_cost_first", 1},
                {"sah_cost_last", 1},
                {"mrays_per_s", 2},
                {"update_vs_embree_refit", 2},
                {"frame_vs_best_embree", 2},
                {"frame_vs_embree_matched", 2}});
}

}  // namespace

BenchReport run_frames_bench(const FramesBenchConfig& config) {
  const BenchOptions& o = config.common;
  check_bench_options(o);
  if (config.frames < 0) throw OptionError("frames", "must be at least 1");
  const int frames = config.frames > 0 ? config.frames : (o.quick ? 3 : 10);
  const size_t tris = config.tris > 0 ? config.tris : (o.quick ? 20'000 : 1'000'000);
  const int threads = resolve_threads(o.threads);
  const float factor =
      config.adaptive_factor > 0.0f ? config.adaptive_factor : BackendOptions{}.adaptive_factor;
  if (config.adaptive_factor < 0.0f || !(factor >= 1.0f))
    throw OptionError("adaptive_factor", "must be at least 1");

  BenchInput input = config.input.empty() ? generated_input(tris) : file_input(config.input);
  if (input.scene.triangle_count() == 0) throw InputError(input.source, "no triangles to animate");
  if (o.quick) {  // a small image: the run is about the loop, not the numbers
    input.scene.camera.width = 160;
    input.scene.camera.height = 120;
  }
  std::vector<AnimCase> cases;
  if (input.scene.animation.animated()) {
    AnimCase c;
    c.name = "scene";
    c.frames = std::min(frames, input.scene.animation.frames - 1);
    if (c.frames < 1) throw InputError(input.source, "the animation has fewer than 2 frames");
    c.scene = std::move(input.scene);
    cases.push_back(std::move(c));
  } else {
    cases = default_cases(input.scene, frames);
  }

  BenchReport report("frames", "Deformable scenes: per-frame update + render, bvh vs Embree", o);
  report.set_param("input", input.source);
  report.set_param("threads", threads);
  report.set_param("frames", frames);
  report.set_param("adaptive_factor", factor);
  report.set_param("triangles", cases.front().scene.triangle_count());
  report.set_param("image", std::to_string(cases.front().scene.camera.width) + "x" +
                                std::to_string(cases.front().scene.camera.height));
  Table& table = report.add_table("frames", "Per-frame times (median over frames)", make_table());

  // --backend adds a row: that backend with its own update() (a plugin
  // without one builds again).
  std::vector<FrameConfig> configs(std::begin(kConfigs), std::end(kConfigs));
  if (!config.backend.empty())
    configs.push_back(
        {config.backend.c_str(), config.backend.c_str(), UpdateStrategy::kAdaptive, "medium"});
  Progress progress("bench frames", cases.size() * configs.size() * size_t(frames), o.progress);
  for (const AnimCase& ac : cases) {
    std::vector<CaseResult> results;
    for (const FrameConfig& fc : configs)
      results.push_back(run_config(ac, fc, threads, factor, progress));
    const double embree_update = results[kEmbreeRefitRow].update.mean_ms;
    double best_embree_frame = results[kEmbreeRefitRow].frame.mean_ms;
    double best_matched[2] = {0.0, 0.0};  // fastest Embree frame, [careful()]
    for (size_t i = 0; i < results.size(); ++i) {
      if (std::string(configs[i].backend) != "embree") continue;
      const double f = results[i].frame.mean_ms;
      best_embree_frame = std::min(best_embree_frame, f);
      double& m = best_matched[configs[i].careful() ? 1 : 0];
      m = m > 0.0 ? std::min(m, f) : f;
    }
    for (size_t i = 0; i < results.size(); ++i) {
      const CaseResult& r = results[i];
      const bool bvh = std::string(configs[i].backend) == "bvh";
      auto row = table.new_row();
      row.set("case", ac.name)
          .set("config", configs[i].label)
          .set("default", i == 0)
          .set("triangles", ac.scene.triangle_count())
          .set("threads", threads)
          .set("frames", ac.frames)
          .set("build_ms", r.build_ms)
          .set("update_ms", r.update.median_ms)
          .set("update_min_ms", r.update.min_ms)
          .set("update_max_ms", r.update.max_ms)
          .set("update_mean_ms", r.update.mean_ms)
          .set("render_ms", r.render.median_ms)
          .set("render_min_ms", r.render.min_ms)
          .set("render_max_ms", r.render.max_ms)
          .set("frame_ms", r.frame.median_ms)
          .set("frame_min_ms", r.frame.min_ms)
          .set("frame_max_ms", r.frame.max_ms)
          .set("frame_mean_ms", r.frame.mean_ms)
          .set("deform_ms", r.deform.median_ms)
          .set("rebuilds", r.rebuilds)
          .set("updates", r.updates)
          .set("mrays_per_s", r.mrays_per_s)
          .set("update_vs_embree_refit",
               embree_update > 0.0 ? r.update.mean_ms / embree_update : 0.0)
          .set("frame_vs_best_embree",
               best_embree_frame > 0.0 ? r.frame.mean_ms / best_embree_frame : 0.0);
      const double matched = best_matched[configs[i].careful() ? 1 : 0];
      row.set("frame_vs_embree_matched", matched > 0.0 ? r.frame.mean_ms / matched : 0.0);
      if (bvh) row.set("sah_cost_first", r.sah_first).set("sah_cost_last", r.sah_last);
    }
  }
  progress.finish();
  table.add_note(
      "update_ms: the backend's update() after the deformer moved the vertices (deform_ms, "
      "the same for every row, is not in frame_ms); frame_ms = update + render (medians; "
      "*_mean_ms: means); build_ms: the initial build at frame 0, in neither.");
  table.add_note(
      "Ratios, of means over the frames (the animation's total time / frames, so an adaptive "
      "strategy's rebuild frames count in full, which the medians hide): update_vs_embree_refit "
      "= update mean / Embree dynamic refit's; frame_vs_best_embree = frame mean / the fastest "
      "Embree row's (< 1: faster than Embree); "
      "frame_vs_embree_matched: the same against the fastest Embree row of matching numerics, "
      "watertight bvh rows against Embree's robust rows, the Möller–Trumbore rows (mt) and "
      "Embree's default rows against each other (`hprt bench frontier` counts the rays each "
      "gets wrong).");
  table.add_note(
      "default: the row that runs with the default options (no flags): bvh auto, which each "
      "frame keeps the refitted tree or rebuilds it with the Morton or the SAH builder, "
      "whichever its measured rebuild and query times say is cheaper over the coming frames "
      "(a frame it predicts to rebuild skips the refit). "
      "updates: per timed frame, r refit, m Morton rebuild, s SAH rebuild, b rebuild (Embree).");
  table.add_note(
      "bvh adaptive refits while the refitted SAH cost stays within adaptive_factor (see the "
      "parameters) x the cost at the last rebuild; rebuilds counts the frames that rebuilt. Embree "
      "low "
      "quality rebuilds its (two-level, Morton) BVH every frame; refit quality refits its first "
      "SAH tree. The morton rows build with --builder morton (Morton codes, no SAH: "
      "a fast build of a dearer tree).");
  return report;
}

}  // namespace hprt::bench
