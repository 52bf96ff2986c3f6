// `hprt render SCENE [--backend bvh|embree|plugin:PATH.so] [BACKEND OPTIONS] [--width W]
// [--height H] [--focal MM] [--threads N] [--frames A:B] -o OUT.png|OUT_%04d.png
// [--json]`: builds a backend over the scene, renders it Whitted style
// (src/render) and writes the image; a one-line summary goes to stderr, --json
// to stdout. An animated scene renders frame 0 without --frames; with it,
// frames A..B-1: frame A built, later ones animated in place and updated
// (--update), one JSON line per frame and a summary on stderr.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "anim/scene_animator.h"
#include "backends/intersector.h"
#include "bench/bench_timing.h"
#include "cli/commands.h"
#include "cli/frame_range.h"
#include "cli/malformed_warning.h"
#include "core/error.h"
#include "core/frame_pattern.h"
#include "core/parallel.h"
#include "core/stopwatch.h"
#include "io/image/image_io.h"
#include "io/scene/scene_reader.h"
#include "render/animation_loop.h"
#include "render/camera_override.h"
#include "render/framebuffer.h"
#include "render/progress.h"
#include "render/tile_scheduler.h"
#include "render/whitted.h"

namespace hprt::cli {
namespace {

constexpr int kTileSize = 32;

struct RenderArgs {
  std::string scene;
  std::string output;
  int width = 0;  // 0: the scene's
  int height = 0;
  float focal_mm = 0.0f;
  std::string frames;  // "A:B"; empty: one still image (frame 0 of an animated scene)
  bool json = false;
  BackendCliOptions backend;
};

// What one rendered frame reports (a frame loop for animated scenes adds
// per-frame update times next to these).
struct FrameReport {
  double render_ms = 0.0;
  RenderStats stats;
  std::string output;
};

Camera render_camera(const Camera& scene_camera, const RenderArgs& a) {
  return override_camera(scene_camera, a.width, a.height, a.focal_mm);
}

// Renders one frame with an already built backend and writes it.
FrameReport render_frame(const Scene& scene, const Camera& camera, const Intersector& backend,
                         const std::string& output) {
  FrameReport report;
  const size_t tiles = make_tiles(camera.width, camera.height, kTileSize).size();
  Framebuffer fb;
  {
    Progress progress("render", tiles);
    RenderOptions options;
    options.tile_size = kTileSize;
    options.progress = &progress;
    const auto start = Clock::now();
    fb = render_whitted(scene, camera, backend, &report.stats, options);
    report.render_ms = ms_since(start);
  }
  write_image(output, fb.width(), fb.height(), fb.pixels());
  report.output = output;
  return report;
}

double mrays_per_s(const FrameReport& f) {
  return f.render_ms > 0.0 ? double(f.stats.rays()) / (f.render_ms * 1e3) : 0.0;
}

// The `strategy` a frame line reports: the bvh update policy, or Embree's
// dynamic-scene commit at its build quality.
std::string strategy_name(const BackendOptions& options, const BackendCliOptions& cli) {
  return options.backend == "embree" ? "embree-" + cli.quality : cli.update;
}

void run_still(const RenderArgs& a) {
  check_image_output(a.output);  // unknown extension or missing directory: fail before work
  const BackendOptions options = finish_backend_options(a.backend);
  Scene scene = load_scene(a.scene);
  const Camera camera = render_camera(scene.camera, a);

  BuildInfo info;
  FrameReport frame;
  int threads = 0;
  run_with_threads(options.threads, [&] {
    threads = resolve_threads(options.threads);
    if (scene.animation.animated()) SceneAnimator(scene).apply(0, scene);  // = --frames 0:1
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    backend->build(scene);
    info = backend->info();
    frame = render_frame(scene, camera, *backend, a.output);
    info.malformed_answers = backend->info().malformed_answers;
  });

  const uint64_t rays = frame.stats.rays();
  const double mrays = mrays_per_s(frame);
  std::fprintf(stderr,
               "hprt render: %s, %zu triangles, %dx%d, %d threads: build %.2f ms, render %.2f "
               "ms, %llu rays (%llu primary, %llu shadow, %llu reflection), %.2f Mrays/s -> %s\n",
               info.name.c_str(), scene.triangle_count(), camera.width, camera.height, threads,
               info.build_ms, frame.render_ms, (unsigned long long)rays,
               (unsigned long long)frame.stats.primary_rays,
               (unsigned long long)frame.stats.shadow_rays,
               (unsigned long long)frame.stats.reflection_rays, mrays, a.output.c_str());
  cli::warn_malformed("hprt render", info.name, info.malformed_answers);
  if (a.json) {
    nlohmann::json j;
    j["backend"] = options.backend;
    j["config"] = info.name;
    j["malformed_answers"] = info.malformed_answers;
    j["width"] = camera.width;
    j["height"] = camera.height;
    j["triangles"] = scene.triangle_count();
    j["threads"] = threads;
    j["build_ms"] = info.build_ms;
    j["render_ms"] = frame.render_ms;
    j["rays"] = rays;
    j["primary_rays"] = frame.stats.primary_rays;
    j["shadow_rays"] = frame.stats.shadow_rays;
    j["reflection_rays"] = frame.stats.reflection_rays;
    j["mrays_per_s"] = mrays;
    j["output"] = frame.output;
    std::cout << j.dump() << std::endl;
  }
}

// --frames A:B: frame A is animated and built from scratch, each later frame
// animated in place and brought up to date with backend->update().
void run_frames(const RenderArgs& a) {
  const BackendOptions options = finish_backend_options(a.backend);
  FrameRange probe = parse_frame_range(a.frames, 1'000'000'000);  // syntax before any work
  const bool numbered = has_frame_number(a.output, "--output");
  if (probe.count() > 1 && !numbered)
    throw InputError("--output", "'" + a.output + "' renders " + std::to_string(probe.count()) +
                                     " frames: it needs a frame number conversion such as "
                                     "%04d (out_%04d.png)");
  check_image_output(format_frame_path(a.output, probe.first));
  Scene scene = load_scene(a.scene);
  const Camera camera = render_camera(scene.camera, a);
  const std::string strategy = strategy_name(options, a.backend);

  struct FrameTimes {
    double animate_ms, update_ms, render_ms;
    bool rebuilt;
  };
  std::vector<FrameTimes> times;
  int threads = 0;
  std::string config;
  uint64_t malformed = 0;
  run_with_threads(options.threads, [&] {
    threads = resolve_threads(options.threads);
    const SceneAnimator animator(scene);
    const FrameRange range = parse_frame_range(a.frames, animator.frames());
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    FrameReport frame;
    const auto render_one = [&](int k, RenderStats& stats) {
      frame = render_frame(scene, camera, *backend, format_frame_path(a.output, k));
      stats = frame.stats;
      return frame.render_ms;
    };
    const auto report = [&](const AnimationFrame& f) {
      const BuildInfo& info = f.info;
      config = info.name;
      times.push_back({f.animate_ms, f.update_ms, f.render_ms, info.rebuilt});
      const std::string update = !info.rebuilt               ? "refit"
                                 : info.rebuilt_with.empty() ? "rebuilt"
                                                             : "rebuilt, " + info.rebuilt_with;
      std::fprintf(stderr, "hprt render: frame %d: update %.2f ms (%s), render %.2f ms -> %s\n",
                   f.frame, f.update_ms, update.c_str(), f.render_ms, frame.output.c_str());
      if (a.json) {
        nlohmann::json j;
        j["frame"] = f.frame;
        j["strategy"] = strategy;
        j["update_ms"] = f.update_ms;
        j["sah_cost"] =
            info.has_tree_stats ? nlohmann::json(info.stats.sah_cost) : nlohmann::json();
        j["rebuilt"] = info.rebuilt;
        j["rebuilt_with"] = info.rebuilt_with;
        j["render_ms"] = f.render_ms;
        j["mrays_per_s"] = mrays_per_s(frame);
        j["output"] = frame.output;
        j["animate_ms"] = f.animate_ms;
        j["rays"] = frame.stats.rays();
        j["backend"] = options.backend;
        j["config"] = info.name;
        j["triangles"] = scene.triangle_count();
        j["width"] = camera.width;
        j["height"] = camera.height;
        j["threads"] = threads;
        std::cout << j.dump() << std::endl;
      }
    };
    run_animation(scene, animator, *backend, {range.first, range.end, true}, render_one, report);
    malformed = backend->info().malformed_answers;
  });

  std::vector<double> update, render;
  double update_total = 0.0, render_total = 0.0;
  int rebuilds = 0;
  for (const FrameTimes& t : times) {
    update.push_back(t.update_ms);
    render.push_back(t.render_ms);
    update_total += t.update_ms;
    render_total += t.render_ms;
    rebuilds += t.rebuilt ? 1 : 0;
  }
  std::fprintf(stderr,
               "hprt render: %zu frame%s (%s), %s, %s, %zu triangles, %dx%d, %d threads: update "
               "median %.2f ms, total %.2f ms (%d rebuilds incl. the first build); render median "
               "%.2f ms, total %.2f ms\n",
               times.size(), times.size() == 1 ? "" : "s", a.frames.c_str(), config.c_str(),
               strategy.c_str(), scene.triangle_count(), camera.width, camera.height, threads,
               bench::summarize_ms(update).median_ms, update_total, rebuilds,
               bench::summarize_ms(render).median_ms, render_total);
  cli::warn_malformed("hprt render", config, malformed);
}

void run_render(const RenderArgs& a) {
  if (a.frames.empty())
    run_still(a);
  else
    run_frames(a);
}

}  // namespace

void add_render_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "render a scene (Whitted: shadows, reflections)");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("-o,--output", args->output,
                  "output image; format from the extension (.png 8-bit sRGB, .exr float linear); "
                  "with --frames a pattern with one %d-style frame number, e.g. out_%04d.png")
      ->required();
  cmd->add_option("--width", args->width, "image width (overrides the scene camera)")
      ->check(CLI::Range(1, kMaxImageSide));
  cmd->add_option("--height", args->height, "image height (overrides the scene camera)")
      ->check(CLI::Range(1, kMaxImageSide));
  cmd->add_option("--focal", args->focal_mm, "focal length in mm (overrides the scene camera)")
      ->check(CLI::Range(kMinLensMm, kMaxLensMm));
  cmd->add_option("--frames", args->frames,
                  "animated scene: render frames A to B-1 (A:B), building at A and updating the "
                  "acceleration structure per --update after that; without it an animated scene "
                  "renders frame 0 (the same image as --frames 0:1)");
  cmd->add_flag("--json", args->json,
                "print one JSON object on stdout (with --frames: one line per frame)");
  add_backend_options(*cmd, args->backend);
  cmd->callback([args] { run_render(*args); });
}

}  // namespace hprt::cli
