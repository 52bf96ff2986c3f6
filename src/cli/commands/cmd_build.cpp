// `hprt build SCENE [--builder B] [--bins K] [--leaf-size N] [--threads T]
// [--repeat R] [--json]`: builds the bvh backend over the scene (prim info +
// builder + flatten, timed), R times when asked (median build time), and
// reports tree quality and memory: a table on stderr, --json on stdout.
#include <sys/resource.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "bench/bench_options.h"
#include "bench/bench_timing.h"
#include "cli/commands.h"
#include "core/parallel.h"
#include "io/scene/scene_reader.h"

namespace hprt::cli {
namespace {

struct BuildArgs {
  std::string scene;
  bool json = false;
  int repeat = 1;
  BackendCliOptions backend;
};

size_t peak_memory_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return size_t(u.ru_maxrss) * 1024;  // Linux reports kilobytes
}

void run_build(const BuildArgs& a) {
  BackendOptions options = finish_backend_options(a.backend);
  options.backend = "bvh";
  const Scene scene = load_scene(a.scene);
  BuildInfo info;
  std::vector<double> times;
  int threads = 0;
  run_with_threads(options.threads, [&] {
    threads = resolve_threads(options.threads);
    for (int r = 0; r < a.repeat; ++r) {
      std::unique_ptr<Intersector> bvh = make_intersector("bvh", options);
      bvh->build(scene);
      info = bvh->info();
      times.push_back(info.build_ms);
    }
  });
  const TreeStats& s = info.stats;
  const double build_ms = bench::summarize_ms(times).median_ms;
  const double bytes_per_tri = s.triangles ? double(info.memory_bytes) / double(s.triangles) : 0.0;
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016" PRIx64, s.tree_hash);
  const std::string builder(to_string(options.build.builder));
  const std::string layout(to_string(options.layout));  // what bytes / triangle measures

  std::fprintf(stderr, "hprt build: %s (%s)\n", a.scene.c_str(), info.name.c_str());
  std::fprintf(stderr, "  %-20s %s\n", "builder", builder.c_str());
  std::fprintf(stderr, "  %-20s %d\n", "threads", threads);
  std::fprintf(stderr, "  %-20s %d\n", "bins", options.build.bins);
  std::fprintf(stderr, "  %-20s %d\n", "leaf size (max)", options.build.max_leaf_size);
  std::fprintf(stderr, "  %-20s C_t %g, C_i %g per %d triangle%s\n", "SAH constants",
               options.build.sah.traversal_cost, options.build.sah.intersection_cost,
               options.build.sah.leaf_block, options.build.sah.leaf_block == 1 ? "" : "s");
  std::fprintf(stderr, "  %-20s %s\n", "layout", layout.c_str());
  std::fprintf(stderr, "  %-20s %zu (+%zu invalid)\n", "triangles", s.triangles,
               s.invalid_triangles);
  std::fprintf(stderr, "  %-20s %zu (%zu leaves)\n", "nodes", s.nodes, s.leaves);
  std::fprintf(stderr, "  %-20s %d\n", "depth", s.depth);
  std::fprintf(stderr, "  %-20s %.3f avg, %d max\n", "leaf size", s.avg_leaf_size, s.max_leaf_size);
  std::fprintf(stderr, "  %-20s %.4f\n", "SAH cost", s.sah_cost);
  std::fprintf(stderr, "  %-20s %.3f ms%s\n", "build", build_ms,
               a.repeat > 1 ? (" (median of " + std::to_string(a.repeat) + ")").c_str() : "");
  std::fprintf(stderr, "  %-20s %.1f\n", "bytes / triangle", bytes_per_tri);
  std::fprintf(stderr, "  %-20s %s\n", "tree hash", hash);
  if (a.json) {
    nlohmann::json j;
    j["scene"] = a.scene;
    j["builder"] = builder;
    j["threads"] = threads;
    j["bins"] = options.build.bins;
    j["leaf_size"] = options.build.max_leaf_size;
    j["sah_traversal_cost"] = options.build.sah.traversal_cost;
    j["sah_intersection_cost"] = options.build.sah.intersection_cost;
    j["sah_leaf_block"] = options.build.sah.leaf_block;
    j["layout"] = layout;
    j["triangles"] = s.triangles;
    j["invalid_triangles"] = s.invalid_triangles;
    j["nodes"] = s.nodes;
    j["leaves"] = s.leaves;
    j["depth"] = s.depth;
    j["avg_leaf_size"] = s.avg_leaf_size;
    j["max_leaf_size"] = s.max_leaf_size;
    j["sah_cost"] = s.sah_cost;
    j["build_ms"] = build_ms;
    j["build_ms_all"] = times;
    j["repeat"] = a.repeat;
    j["tree_hash"] = hash;
    j["memory_bytes"] = info.memory_bytes;
    j["bytes_per_triangle"] = bytes_per_tri;
    j["peak_memory_bytes"] = peak_memory_bytes();
    std::cout << j.dump() << std::endl;
  }
}

}  // namespace

void add_build_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* cmd = app.add_subcommand("build", "build the BVH over a scene and report its quality");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  cmd->add_option("--repeat", args->repeat, "build this many times, report the median time")
      ->check(CLI::Range(1, bench::kMaxRepeat))
      ->capture_default_str();
  add_backend_options(*cmd, args->backend, /*with_backend=*/false);
  cmd->callback([args] { run_build(*args); });
}

}  // namespace hprt::cli
