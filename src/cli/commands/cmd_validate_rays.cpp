// `hprt validate rays SCENE [--rays IN.rays | --kind K -n N [--seed S]]
// [--backend A] [--reference B] [BACKEND OPTIONS] [--occluded] [--threads N]
// [--mismatches OUT.rays] [--json]`: traces the rays through backend A
// (default bvh) and reference B (default embree), settles every mismatch
// with the exact arbiter (validators/ray_diff) and writes the mismatching
// rays for replay. Exit 1 when A is wrong on some ray.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "cli/commands.h"
#include "cli/output_path.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/rays/ray_file.h"
#include "io/scene/scene_reader.h"
#include "validators/ray_diff.h"
#include "validators/ray_diff_summary.h"
#include "validators/ray_sets.h"

namespace hprt::cli {
namespace {

struct ValidateRaysArgs {
  std::string scene;
  std::string rays;
  std::string kind;
  double n = 0;
  uint64_t seed = 1;
  bool occluded = false;
  bool json = false;
  std::string mismatches = "mismatches.rays";
  std::string reference = "embree";
  double brute_force_limit = 4e6;
  BackendCliOptions backend;
};

int run_validate_rays(const ValidateRaysArgs& a) {
  if (a.rays.empty() == a.kind.empty())
    throw InputError("--rays/--kind", "give exactly one of --rays FILE or --kind K -n N");
  std::optional<RayKind> kind;
  if (!a.kind.empty()) {
    kind = parse_ray_kind(a.kind);
    if (!(a.n >= 1.0)) throw InputError("-n", "--kind needs -n with at least 1 ray");
    if (a.n > double(kMaxRaySetSize) || a.n != std::floor(a.n))
      throw InputError("-n", "must be a whole number of rays up to 1e9");
  }
  if (!(a.brute_force_limit >= 0.0)) throw InputError("--brute-force-limit", "must be >= 0");
  check_output_directory(a.mismatches);
  BackendOptions options = finish_backend_options(a.backend);
  const Scene scene = load_scene(a.scene);
  std::vector<Ray> rays;
  if (!kind) rays = read_rays(a.rays);

  RayDiffOptions diff_opts;
  diff_opts.brute_force_limit = size_t(a.brute_force_limit);
  RayDiffResult r;
  RayDiffLabels labels;
  labels.occluded = a.occluded;
  run_with_threads(options.threads, [&] {
    std::unique_ptr<Intersector> reference = make_intersector(a.reference, options);
    reference->build(scene);
    std::unique_ptr<Intersector> backend = make_intersector(options.backend, options);
    backend->build(scene);
    if (kind) {
      // Ray sets depend on the seed only: surface points come from Embree
      // whichever backends are compared.
      std::unique_ptr<Intersector> embree;
      if (ray_kind_needs_backend(*kind) && a.reference != "embree") {
        embree = make_intersector("embree", options);
        embree->build(scene);
      }
      rays = make_rays(scene, *kind, size_t(a.n), a.seed, embree ? embree.get() : reference.get());
    }
    r = run_ray_diff(scene, rays, *backend, *reference, a.occluded, diff_opts);
    labels.backend = backend->info().name;
    labels.reference = reference->info().name;
  });

  if (r.mismatches > 0) {
    std::vector<Ray> bad;
    bad.reserve(r.mismatches);
    for (size_t i : r.mismatch_indices) bad.push_back(rays[i]);
    write_rays(a.mismatches, bad);
    labels.mismatches = a.mismatches;
  }
  labels.source =
      kind ? std::string(to_string(*kind)) + ", seed " + std::to_string(a.seed) : a.rays;
  std::fputs(ray_diff_summary(r, labels).c_str(), stderr);
  if (a.json) {
    nlohmann::json j;
    j["rays"] = r.rays;
    j["agree"] = r.agree;
    j["ties"] = r.ties;
    j["mismatches"] = r.mismatches;
    j["bvh_right"] = r.bvh_right;
    j["embree_right"] = r.embree_right;
    j["both_right"] = r.both_right;
    j["both_wrong"] = r.both_wrong;
    j["bvh_wrong"] = r.bvh_wrong();
    j["max_rel_t_error"] = r.max_rel_t_error;
    j["max_rel_t_error_arbiter"] = r.max_rel_t_error_arbiter;
    j["query"] = a.occluded ? "occluded" : "closest";
    j["bvh_config"] = labels.backend;
    j["embree_config"] = labels.reference;
    j["backend_config"] = labels.backend;
    j["reference_config"] = labels.reference;
    j["bvh_malformed"] = r.bvh_malformed;
    j["embree_malformed"] = r.embree_malformed;
    j["kind"] = kind ? nlohmann::json(std::string(to_string(*kind))) : nlohmann::json(nullptr);
    j["rays_file"] = kind ? nlohmann::json(nullptr) : nlohmann::json(a.rays);
    j["triangles"] = scene.triangle_count();
    j["brute_force"] = r.brute_force;
    j["mismatches_file"] =
        labels.mismatches.empty() ? nlohmann::json(nullptr) : nlohmann::json(labels.mismatches);
    j["pass"] = r.bvh_wrong() == 0;
    std::cout << j.dump() << std::endl;
  }
  return r.bvh_wrong() == 0 ? 0 : 1;
}

}  // namespace

void add_validate_rays_command(CLI::App& validate, CommandState& state) {
  auto args = std::make_shared<ValidateRaysArgs>();
  CLI::App* cmd = validate.add_subcommand(
      "rays",
      "trace rays through two backends (default bvh and embree); settle mismatches with an "
      "exact arbiter");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("--rays", args->rays, "input .rays file");
  cmd->add_option("--kind", args->kind, "generate rays of this kind instead")
      ->check(CLI::IsMember(ray_kind_names()));
  cmd->add_option("-n", args->n, "number of generated rays");
  cmd->add_option("--seed", args->seed, "random seed")->capture_default_str();
  cmd->add_flag("--occluded", args->occluded, "compare occlusion (any hit) instead of closest hit");
  cmd->add_option("--mismatches", args->mismatches, "write the mismatching rays here (.rays)")
      ->capture_default_str();
  cmd->add_option("--brute-force-limit", args->brute_force_limit,
                  "arbitrate over every triangle the ray's line may cross up to this many "
                  "triangles (else only the backends' answers)")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  add_backend_options(*cmd, args->backend);
  add_reference_option(*cmd, args->reference);
  cmd->callback([args, &state] { state.exit_code = run_validate_rays(*args); });
}

}  // namespace hprt::cli
