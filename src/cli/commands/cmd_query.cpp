// `hprt query SCENE --rays IN.rays|--points IN.points --kind
// count|all|inside|closest [--max-hits N] [--max-distance D] -o OUT`: builds
// a backend and answers one query, writing the files of io/rays/ray_file.h:
// over every hit along each ray, count (crossings in (tnear, tfar], one
// uint32 per ray) or all (per ray a uint32 count and that many .hits records,
// nearest first); per point, inside (one byte: 0 outside, 1 inside, 2 on
// the surface) or closest (32-byte records). A summary goes to stderr,
// --json to stdout.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <numeric>
#include <string>

#include "backends/intersector.h"
#include "cli/commands.h"
#include "cli/output_path.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/stopwatch.h"
#include "io/rays/ray_file.h"
#include "io/scene/scene_reader.h"

namespace hprt::cli {
namespace {

struct QueryArgs {
  std::string scene;
  std::string rays;
  std::string points;
  std::string output;
  std::string kind;
  uint32_t max_hits = 1024;
  float max_distance = std::numeric_limits<float>::infinity();
  bool json = false;
  BackendCliOptions backend;
};

bool is_point_query(const std::string& kind) { return kind == "inside" || kind == "closest"; }

// What one query produced, for the summary.
struct QueryResult {
  size_t queries = 0;  // rays or points
  uint64_t total = 0;  // count/all: hits; inside: points inside; closest: points with one found
  size_t on_surface = 0;
  size_t truncated = 0;
  double query_ms = 0.0;
};

void run_query(const QueryArgs& a) {
  const bool points_kind = is_point_query(a.kind);
  if (points_kind && a.points.empty())
    throw OptionError("points", "--kind " + a.kind + " needs --points FILE");
  if (!points_kind && a.rays.empty())
    throw OptionError("rays", "--kind " + a.kind + " needs --rays FILE");
  if (points_kind && !a.rays.empty())
    throw OptionError("rays", "--kind " + a.kind + " takes --points, not --rays");
  if (!points_kind && !a.points.empty())
    throw OptionError("points", "--kind " + a.kind + " takes --rays, not --points");
  check_output_directory(a.output);
  const BackendOptions options = finish_backend_options(a.backend);
  const Scene scene = load_scene(a.scene);
  const std::vector<Ray> rays = points_kind ? std::vector<Ray>{} : read_rays(a.rays);
  const std::vector<Vec3f> points = points_kind ? read_points(a.points) : std::vector<Vec3f>{};

  std::vector<uint32_t> counts;
  HitLists lists;
  std::vector<PointLocation> locations;
  std::vector<ClosestPoint> closest;
  BuildInfo info;
  QueryResult r;
  r.queries = points_kind ? points.size() : rays.size();
  int threads = 0;
  run_with_threads(options.threads, [&] {
    threads = resolve_threads(options.threads);
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    backend->build(scene);
    info = backend->info();
    const auto start = Clock::now();
    if (a.kind == "all") {
      backend->intersect_all(rays, a.max_hits, lists);
    } else if (a.kind == "count") {
      counts.resize(rays.size());
      backend->count(rays, counts);
    } else if (a.kind == "inside") {
      locations.resize(points.size());
      backend->locate(points, locations);
    } else {
      closest.resize(points.size());
      backend->closest(points, a.max_distance, closest);
    }
    r.query_ms = ms_since(start);
  });

  const char* what = "hits";
  if (a.kind == "all") {
    r.total = lists.hits.size();
    r.truncated =
        size_t(std::accumulate(lists.truncated.begin(), lists.truncated.end(), size_t(0)));
    write_hit_lists(a.output, lists);
  } else if (a.kind == "count") {
    r.total = std::accumulate(counts.begin(), counts.end(), uint64_t(0));
    write_counts(a.output, counts);
  } else if (a.kind == "inside") {
    for (PointLocation l : locations) {
      r.total += l == PointLocation::kInside;
      r.on_surface += l == PointLocation::kOnSurface;
    }
    what = "inside";
    write_locations(a.output, locations);
  } else {
    for (const ClosestPoint& c : closest) r.total += c.found();
    what = "found";
    write_closest(a.output, closest);
  }
  const double mq = r.query_ms > 0.0 ? double(r.queries) / (r.query_ms * 1e3) : 0.0;
  std::fprintf(stderr,
               "hprt query: %s, %zu triangles, %zu %s (%s), %llu %s, build %.2f ms, query "
               "%.2f ms, %.2f M%s/s, %d threads -> %s\n",
               info.name.c_str(), scene.triangle_count(), r.queries,
               points_kind ? "points" : "rays", a.kind.c_str(),
               static_cast<unsigned long long>(r.total), what, info.build_ms, r.query_ms, mq,
               points_kind ? "points" : "rays", threads, a.output.c_str());
  if (a.kind == "inside" && r.on_surface > 0)
    std::fprintf(stderr, "hprt query: %zu points exactly on the surface\n", r.on_surface);
  if (r.truncated > 0)
    std::fprintf(stderr, "hprt query: %zu rays had more than --max-hits %u hits (nearest kept)\n",
                 r.truncated, a.max_hits);
  if (a.json) {
    nlohmann::json j;
    j["backend"] = options.backend;
    j["backend_config"] = info.name;
    j["kind"] = a.kind;
    j["triangles"] = scene.triangle_count();
    if (points_kind) {
      j["points"] = points.size();
      j["mpoints_per_s"] = mq;
    } else {
      j["rays"] = rays.size();
      j["mrays_per_s"] = mq;
    }
    if (a.kind == "count" || a.kind == "all") j["hits"] = r.total;
    if (a.kind == "all") {
      j["max_hits"] = a.max_hits;
      j["truncated_rays"] = r.truncated;
    }
    if (a.kind == "inside") {
      j["inside"] = r.total;
      j["on_surface"] = r.on_surface;
    }
    if (a.kind == "closest") {
      j["found"] = r.total;
      if (std::isfinite(a.max_distance)) j["max_distance"] = a.max_distance;
    }
    j["ms"] = r.query_ms;
    j["build_ms"] = info.build_ms;
    j["threads"] = threads;
    j["output"] = a.output;
    std::cout << j.dump() << std::endl;
  }
}

}  // namespace

void add_query_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<QueryArgs>();
  CLI::App* cmd = app.add_subcommand(
      "query",
      "queries beyond the closest hit: crossing counts or all hits along rays, inside/outside or "
      "the closest surface point of points");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("--rays", args->rays, "input .rays file (count, all)");
  cmd->add_option("--points", args->points,
                  "input .points file: float32 x, y, z per point (inside, closest)");
  cmd->add_option("--kind", args->kind,
                  "count: crossings in (tnear, tfar], one uint32 per ray; all: per ray a uint32 "
                  "count and that many .hits records, nearest first; inside: one byte per point "
                  "(0 outside, 1 inside, 2 on the surface); closest: 32 bytes per point (float32 "
                  "x, y, z, distance, u, v; uint32 geomID, primID)")
      ->required()
      ->check(CLI::IsMember({"count", "all", "inside", "closest"}));
  cmd->add_option("--max-hits", args->max_hits,
                  "all: hits kept per ray, the nearest (default 1024)")
      ->check(CLI::Range(1u, 1u << 24));
  cmd->add_option("--max-distance", args->max_distance,
                  "closest: search radius (inclusive); farther points get distance inf and "
                  "invalid IDs (default: no bound)")
      ->check(non_negative_validator());
  cmd->add_option("-o,--output", args->output, "output file")->required();
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  add_backend_options(*cmd, args->backend);
  cmd->callback([args] { run_query(*args); });
}

}  // namespace hprt::cli
