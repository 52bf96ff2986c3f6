// `hprt render SCENE [--backend bvh|embree] [BACKEND OPTIONS] [--width W]
// [--height H] [--focal MM] [--threads N] -o OUT.png|OUT.exr [--json]`:
// builds a backend over the scene, renders it Whitted style (src/render) and
// writes the image; a one-line summary goes to stderr, --json to stdout.
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "backends/intersector.h"
#include "cli/commands.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "io/scene_reader.h"
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

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// --width/--height/--focal override the scene camera. One of width/height
// alone keeps the scene's aspect ratio.
Camera render_camera(const Camera& scene_camera, const RenderArgs& a) {
  Camera c = scene_camera;
  const double aspect = double(scene_camera.height) / double(scene_camera.width);
  if (a.width > 0) c.width = a.width;
  if (a.height > 0) c.height = a.height;
  if (a.width > 0 && a.height == 0) c.height = std::max(1, int(std::lround(a.width * aspect)));
  if (a.height > 0 && a.width == 0) c.width = std::max(1, int(std::lround(a.height / aspect)));
  if (a.focal_mm > 0.0f) c.focal_length_mm = a.focal_mm;
  return c;
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
    const auto start = std::chrono::steady_clock::now();
    fb = render_whitted(scene, camera, backend, &report.stats, options);
    report.render_ms = ms_since(start);
  }
  write_image(output, fb.width(), fb.height(), fb.pixels());
  report.output = output;
  return report;
}

void run_render(const RenderArgs& a) {
  check_image_output(a.output);  // unknown extension or missing directory: fail before work
  const BackendOptions options = finish_backend_options(a.backend);
  const Scene scene = load_scene(a.scene);
  const Camera camera = render_camera(scene.camera, a);

  BuildInfo info;
  FrameReport frame;
  int threads = 0;
  run_with_threads(options.threads, [&] {
    threads = resolve_threads(options.threads);
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    backend->build(scene);
    info = backend->info();
    frame = render_frame(scene, camera, *backend, a.output);
  });

  const uint64_t rays = frame.stats.rays();
  const double mrays = frame.render_ms > 0.0 ? double(rays) / (frame.render_ms * 1e3) : 0.0;
  std::fprintf(stderr,
               "hprt render: %s, %zu triangles, %dx%d, %d threads: build %.2f ms, render %.2f "
               "ms, %llu rays (%llu primary, %llu shadow, %llu reflection), %.2f Mrays/s -> %s\n",
               info.name.c_str(), scene.triangle_count(), camera.width, camera.height, threads,
               info.build_ms, frame.render_ms, (unsigned long long)rays,
               (unsigned long long)frame.stats.primary_rays,
               (unsigned long long)frame.stats.shadow_rays,
               (unsigned long long)frame.stats.reflection_rays, mrays, a.output.c_str());
  if (a.json) {
    nlohmann::json j;
    j["backend"] = options.backend;
    j["config"] = info.name;
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

}  // namespace

void add_render_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "render a scene (Whitted: shadows, reflections)");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("-o,--output", args->output,
                  "output image; format from the extension (.png 8-bit sRGB, .exr float linear)")
      ->required();
  cmd->add_option("--width", args->width, "image width (overrides the scene camera)")
      ->check(CLI::Range(1, 65536));
  cmd->add_option("--height", args->height, "image height (overrides the scene camera)")
      ->check(CLI::Range(1, 65536));
  cmd->add_option("--focal", args->focal_mm, "focal length in mm (overrides the scene camera)")
      ->check(CLI::Range(0.1f, 100000.0f));
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  add_backend_options(*cmd, args->backend);
  cmd->callback([args] { run_render(*args); });
}

}  // namespace hprt::cli
