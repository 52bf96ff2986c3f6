// `hprt query SCENE --rays IN.rays --kind count|all [--max-hits N] -o OUT`:
// builds a backend and answers a query over every hit along each ray: count
// (crossings in (tnear, tfar], one uint32 per ray) or all (per ray a uint32
// count and that many .hits records, nearest first). A summary goes to
// stderr, --json to stdout.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <numeric>
#include <string>

#include "backends/intersector.h"
#include "cli/commands.h"
#include "cli/output_path.h"
#include "core/parallel.h"
#include "core/stopwatch.h"
#include "io/rays/ray_file.h"
#include "io/scene/scene_reader.h"

namespace hprt::cli {
namespace {

struct QueryArgs {
  std::string scene;
  std::string rays;
  std::string output;
  std::string kind;
  uint32_t max_hits = 1024;
  bool json = false;
  BackendCliOptions backend;
};

void run_query(const QueryArgs& a) {
  check_output_directory(a.output);
  const BackendOptions options = finish_backend_options(a.backend);
  const Scene scene = load_scene(a.scene);
  const std::vector<Ray> rays = read_rays(a.rays);
  const bool all = a.kind == "all";

  std::vector<uint32_t> counts;
  HitLists lists;
  BuildInfo info;
  double query_ms = 0.0;
  int threads = 0;
  run_with_threads(options.threads, [&] {
    threads = resolve_threads(options.threads);
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    backend->build(scene);
    info = backend->info();
    const auto start = Clock::now();
    if (all) {
      backend->intersect_all(rays, a.max_hits, lists);
    } else {
      counts.resize(rays.size());
      backend->count(rays, counts);
    }
    query_ms = ms_since(start);
  });

  uint64_t total = 0;
  size_t truncated = 0;
  if (all) {
    total = lists.hits.size();
    truncated = size_t(std::accumulate(lists.truncated.begin(), lists.truncated.end(), size_t(0)));
    write_hit_lists(a.output, lists);
  } else {
    total = std::accumulate(counts.begin(), counts.end(), uint64_t(0));
    write_counts(a.output, counts);
  }
  const double mrays = query_ms > 0.0 ? double(rays.size()) / (query_ms * 1e3) : 0.0;
  std::fprintf(stderr,
               "hprt query: %s, %zu triangles, %zu rays (%s), %llu hits, build %.2f ms, query "
               "%.2f ms, %.2f Mrays/s, %d threads -> %s\n",
               info.name.c_str(), scene.triangle_count(), rays.size(), a.kind.c_str(),
               static_cast<unsigned long long>(total), info.build_ms, query_ms, mrays, threads,
               a.output.c_str());
  if (truncated > 0)
    std::fprintf(stderr, "hprt query: %zu rays had more than --max-hits %u hits (nearest kept)\n",
                 truncated, a.max_hits);
  if (a.json) {
    nlohmann::json j;
    j["backend"] = options.backend;
    j["backend_config"] = info.name;
    j["kind"] = a.kind;
    j["triangles"] = scene.triangle_count();
    j["rays"] = rays.size();
    j["hits"] = total;
    if (all) {
      j["max_hits"] = a.max_hits;
      j["truncated_rays"] = truncated;
    }
    j["ms"] = query_ms;
    j["build_ms"] = info.build_ms;
    j["mrays_per_s"] = mrays;
    j["threads"] = threads;
    j["output"] = a.output;
    std::cout << j.dump() << std::endl;
  }
}

}  // namespace

void add_query_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<QueryArgs>();
  CLI::App* cmd = app.add_subcommand(
      "query", "every hit along each ray of a .rays file: crossing counts or all hits");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("--rays", args->rays, "input .rays file")->required();
  cmd->add_option("--kind", args->kind,
                  "count: crossings in (tnear, tfar], one uint32 per ray; all: per ray a uint32 "
                  "count and that many .hits records, nearest first")
      ->required()
      ->check(CLI::IsMember({"count", "all"}));
  cmd->add_option("--max-hits", args->max_hits,
                  "all: hits kept per ray, the nearest (default 1024)")
      ->check(CLI::Range(1u, 1u << 24));
  cmd->add_option("-o,--output", args->output, "output file")->required();
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  add_backend_options(*cmd, args->backend);
  cmd->callback([args] { run_query(*args); });
}

}  // namespace hprt::cli
