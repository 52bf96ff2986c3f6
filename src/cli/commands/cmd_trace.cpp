// `hprt trace SCENE --rays IN.rays [--backend bvh|embree|plugin:PATH.so] [--occluded]
// [--repeat N] -o OUT`:
// builds a backend, traces a .rays file (closest hit or occlusion) and writes
// .hits or one byte per ray; a summary goes to stderr, --json to stdout.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "backends/intersector.h"
#include "bench/bench_options.h"
#include "cli/commands.h"
#include "cli/malformed_warning.h"
#include "cli/output_path.h"
#include "core/parallel.h"
#include "core/stopwatch.h"
#include "io/rays/ray_file.h"
#include "io/scene/scene_reader.h"

namespace hprt::cli {
namespace {

struct TraceArgs {
  std::string scene;
  std::string rays;
  std::string output;
  bool occluded = false;
  bool json = false;
  int repeat = 1;
  BackendCliOptions backend;
};

void run_trace(const TraceArgs& a) {
  check_output_directory(a.output);
  const BackendOptions options = finish_backend_options(a.backend);
  const Scene scene = load_scene(a.scene);
  const std::vector<Ray> rays = read_rays(a.rays);

  std::vector<Hit> hits;
  std::vector<uint8_t> occluded;
  BuildInfo info;
  std::vector<double> times;  // ms of each repetition
  int threads = 0;
  run_with_threads(options.threads, [&] {
    threads = resolve_threads(options.threads);
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    backend->build(scene);
    info = backend->info();
    if (a.occluded)
      occluded.resize(rays.size());
    else
      hits.resize(rays.size());
    for (int r = 0; r < a.repeat; ++r) {  // the same answers every time
      const auto start = Clock::now();
      if (a.occluded)
        backend->occluded(rays, occluded);
      else
        backend->intersect(rays, hits);
      times.push_back(ms_since(start));
    }
    info.malformed_answers = backend->info().malformed_answers;
  });

  // The first trace pays for cold caches and fresh pages; with --repeat the
  // median of all of them is the figure.
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  const double trace_ms = sorted[sorted.size() / 2];
  size_t hit_count = 0;
  if (a.occluded) {
    hit_count = size_t(std::count(occluded.begin(), occluded.end(), uint8_t(1)));
    write_occlusion(a.output, occluded);
  } else {
    hit_count =
        size_t(std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.hit(); }));
    write_hits(a.output, hits);
  }
  const double mrays = trace_ms > 0.0 ? double(rays.size()) / (trace_ms * 1e3) : 0.0;
  std::fprintf(stderr,
               "hprt trace: %s, %zu triangles, %zu rays (%s), %zu %s, build %.2f ms, trace "
               "%.2f ms%s, %.2f Mrays/s, %d threads -> %s\n",
               info.name.c_str(), scene.triangle_count(), rays.size(),
               a.occluded ? "occluded" : "closest hit", hit_count, a.occluded ? "occluded" : "hits",
               info.build_ms, trace_ms,
               a.repeat > 1 ? (" (median of " + std::to_string(a.repeat) + ")").c_str() : "", mrays,
               threads, a.output.c_str());
  cli::warn_malformed("hprt trace", info.name, info.malformed_answers);
  if (a.json) {
    nlohmann::json j;
    j["backend"] = options.backend;
    j["malformed_answers"] = info.malformed_answers;
    j["backend_config"] = info.name;
    j["query"] = a.occluded ? "occluded" : "closest";
    j["triangles"] = scene.triangle_count();
    j["rays"] = rays.size();
    j["hits"] = hit_count;
    j["ms"] = trace_ms;
    j["ms_first"] = times.front();
    j["repeat"] = a.repeat;
    j["build_ms"] = info.build_ms;
    j["mrays_per_s"] = mrays;
    j["threads"] = threads;
    j["memory_bytes"] = info.memory_bytes;
    j["output"] = a.output;
    std::cout << j.dump() << std::endl;
  }
}

}  // namespace

void add_trace_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<TraceArgs>();
  CLI::App* cmd = app.add_subcommand("trace", "trace a .rays file through a backend");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("--rays", args->rays, "input .rays file")->required();
  cmd->add_option("-o,--output", args->output, "output .hits (or occlusion bytes)")->required();
  cmd->add_flag("--occluded", args->occluded, "any-hit query: one byte per ray, 1 = occluded");
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  cmd->add_option("--repeat", args->repeat,
                  "trace the rays this many times in one process and report the median time "
                  "(the first trace also pays for cold caches)")
      ->check(CLI::Range(1, bench::kMaxRepeat));
  add_backend_options(*cmd, args->backend);
  cmd->callback([args] { run_trace(*args); });
}

}  // namespace hprt::cli
