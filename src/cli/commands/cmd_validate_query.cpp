// `hprt validate query SCENE --query count|inside|closest [--rays IN.rays |
// --points IN.points | --kind K -n N [--seed S]] [--max-distance D]
// [--backend A] [--reference B] [BACKEND OPTIONS] [--mismatches OUT]
// [--json]`: answers the query through backend A (default bvh) and
// reference B (default embree), settles every disagreement with an exact
// judge (validators/query_diff.h) and writes the disputed rays or points for
// replay. --kind names a ray kind for count, a point kind for inside and
// closest. Exit 1 when A is wrong on some query.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "cli/commands.h"
#include "cli/output_path.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/rays/ray_file.h"
#include "io/scene/scene_reader.h"
#include "validators/point_sets.h"
#include "validators/query_diff.h"
#include "validators/ray_sets.h"

namespace hprt::cli {
namespace {

struct ValidateQueryArgs {
  std::string scene;
  std::string query;
  std::string rays;
  std::string points;
  std::string kind;
  double n = 0;
  uint64_t seed = 1;
  float max_distance = std::numeric_limits<float>::infinity();
  bool json = false;
  std::string mismatches;
  std::string reference = "embree";
  double brute_force_limit = 4e6;
  BackendCliOptions backend;
};

int run_validate_query(const ValidateQueryArgs& a) {
  const bool count = a.query == "count";
  const std::string& file = count ? a.rays : a.points;
  if (count && !a.points.empty())
    throw OptionError("points", "--query count takes --rays or a ray --kind, not --points");
  if (!count && !a.rays.empty())
    throw OptionError("rays",
                      "--query " + a.query + " takes --points or a point --kind, not --rays");
  if (file.empty() == a.kind.empty())
    throw OptionError(count ? "rays" : "points", std::string("give exactly one of ") +
                                                     (count ? "--rays" : "--points") +
                                                     " FILE or --kind K -n N");
  if (!a.kind.empty()) {
    if (!(a.n >= 1.0)) throw OptionError("n", "--kind needs -n with at least 1 query");
    if (a.n > double(count ? kMaxRaySetSize : kMaxPointSetSize) || a.n != std::floor(a.n))
      throw OptionError("n", "must be a whole number of queries up to 1e9");
  }
  if (!(a.brute_force_limit >= 0.0)) throw OptionError("brute-force-limit", "must be >= 0");
  const std::string mismatches =
      !a.mismatches.empty() ? a.mismatches : (count ? "mismatches.rays" : "mismatches.points");
  check_output_directory(mismatches);
  const BackendOptions options = finish_backend_options(a.backend);
  const Scene scene = load_scene(a.scene);
  std::vector<Ray> rays;
  std::vector<Vec3f> points;
  if (count && !a.rays.empty()) rays = read_rays(a.rays);
  if (!count && !a.points.empty()) points = read_points(a.points);
  if (!count && !a.kind.empty())
    points = make_points(scene, parse_point_kind(a.kind), size_t(a.n), a.seed, a.scene);
  const RayKind ray_kind = count && !a.kind.empty() ? parse_ray_kind(a.kind) : RayKind::kRandom;

  QueryDiffOptions opts;
  opts.brute_force_limit = size_t(a.brute_force_limit);
  opts.max_distance = a.max_distance;
  QueryDiffResult r;
  std::string backend_name, reference_name;
  run_with_threads(options.threads, [&] {
    std::unique_ptr<Intersector> reference = make_intersector(a.reference, options);
    reference->build(scene);
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    backend->build(scene);
    if (count && !a.kind.empty()) {
      std::unique_ptr<Intersector> embree;
      if (ray_kind_needs_backend(ray_kind) && a.reference != "embree") {
        embree = make_intersector("embree", options);
        embree->build(scene);
      }
      rays =
          make_rays(scene, ray_kind, size_t(a.n), a.seed, embree ? embree.get() : reference.get());
    }
    if (count)
      r = run_count_diff(scene, rays, *backend, *reference, opts);
    else if (a.query == "inside")
      r = run_inside_diff(scene, points, *backend, *reference, opts);
    else
      r = run_closest_diff(scene, points, *backend, *reference, opts);
    backend_name = backend->info().name;
    reference_name = reference->info().name;
  });

  bool wrote = false;
  if (r.mismatches > 0) {
    if (count) {
      std::vector<Ray> bad;
      for (size_t i : r.mismatch_indices) bad.push_back(rays[i]);
      write_rays(mismatches, bad);
    } else {
      std::vector<Vec3f> bad;
      for (size_t i : r.mismatch_indices) bad.push_back(points[i]);
      write_points(mismatches, bad);
    }
    wrote = true;
  }
  const std::string source = !a.kind.empty() ? a.kind + ", seed " + std::to_string(a.seed) : file;
  std::string text = query_diff_summary(r, backend_name, reference_name, source);
  if (wrote)
    text += "  disputed " + std::string(count ? "rays" : "points") + " -> " + mismatches + "\n";
  std::fputs(text.c_str(), stderr);
  if (a.json) {
    nlohmann::json j;
    j["query"] = a.query;
    j["queries"] = r.queries;
    j["agree"] = r.agree;
    j["mismatches"] = r.mismatches;
    j["backend_right"] = r.backend_right;
    j["reference_right"] = r.reference_right;
    j["both_right"] = r.both_right;
    j["both_wrong"] = r.both_wrong;
    j["unjudged"] = r.unjudged;
    j["fill_rule"] = r.fill_rule;
    j["backend_wrong"] = r.backend_wrong();
    j["backend_config"] = backend_name;
    j["reference_config"] = reference_name;
    j["kind"] = a.kind.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.kind);
    j["input_file"] = file.empty() ? nlohmann::json(nullptr) : nlohmann::json(file);
    j["triangles"] = scene.triangle_count();
    j["mismatches_file"] = wrote ? nlohmann::json(mismatches) : nlohmann::json(nullptr);
    j["pass"] = r.backend_wrong() == 0;
    std::cout << j.dump() << std::endl;
  }
  return r.backend_wrong() == 0 ? 0 : 1;
}

}  // namespace

void add_validate_query_command(CLI::App& validate, CommandState& state) {
  auto args = std::make_shared<ValidateQueryArgs>();
  CLI::App* cmd = validate.add_subcommand(
      "query",
      "answer count, inside or closest queries through two backends (default bvh and embree); "
      "settle disagreements with an exact judge");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("--query", args->query, "the query to diff")
      ->required()
      ->check(CLI::IsMember({"count", "inside", "closest"}));
  cmd->add_option("--rays", args->rays, "input .rays file (count)");
  cmd->add_option("--points", args->points, "input .points file (inside, closest)");
  std::vector<std::string> kinds = ray_kind_names();
  for (const std::string& k : point_kind_names())
    if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) kinds.push_back(k);
  cmd->add_option("--kind", args->kind,
                  "generate the queries instead: a ray kind for count, a point kind (random, "
                  "near, hard) for inside and closest")
      ->check(CLI::IsMember(kinds));
  cmd->add_option("-n", args->n, "number of generated queries");
  cmd->add_option("--seed", args->seed, "random seed")->capture_default_str();
  cmd->add_option("--max-distance", args->max_distance, "closest: search radius (inclusive)")
      ->check(non_negative_validator());
  cmd->add_option("--mismatches", args->mismatches,
                  "write the disputed rays or points here (default mismatches.rays or "
                  "mismatches.points)");
  cmd->add_option("--brute-force-limit", args->brute_force_limit,
                  "judge disagreements by brute force up to this many triangles")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  add_backend_options(*cmd, args->backend);
  add_reference_option(*cmd, args->reference);
  cmd->callback([args, &state] { state.exit_code = run_validate_query(*args); });
}

}  // namespace hprt::cli
