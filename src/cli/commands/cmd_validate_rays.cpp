// `hprt validate rays SCENE [--rays IN.rays | --kind K -n N [--seed S]]
// [BVH OPTIONS] [--occluded] [--threads N] [--mismatches OUT.rays] [--json]`:
// traces the rays through the bvh and embree backends, settles every
// mismatch with the exact arbiter (validators/ray_diff) and writes the
// mismatching rays for replay. Exit 1 when bvh is wrong on some ray.
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
#include "validators/ray_sets.h"

namespace hprt::cli {
namespace {

constexpr double kMaxRays = 1e9;

struct ValidateRaysArgs {
  std::string scene;
  std::string rays;
  std::string kind;
  double n = 0;
  uint64_t seed = 1;
  bool occluded = false;
  bool json = false;
  std::string mismatches = "mismatches.rays";
  double brute_force_limit = 4e6;
  BackendCliOptions backend;
};

void print_table(const ValidateRaysArgs& a, const RayDiffResult& r, const std::string& bvh_name,
                 const std::string& embree_name, const std::string& source,
                 const std::string& written) {
  auto row = [&](const char* name, size_t v) {
    std::fprintf(stderr, "  %-14s %12zu  %7.3f%%\n", name, v,
                 r.rays ? 100.0 * double(v) / double(r.rays) : 0.0);
  };
  std::fprintf(stderr, "hprt validate rays: %s vs %s, %s, %zu rays (%s)%s\n", bvh_name.c_str(),
               embree_name.c_str(), a.occluded ? "occluded" : "closest hit", r.rays, source.c_str(),
               r.brute_force ? ", arbiter over all triangles" : "");
  row("agree", r.agree);
  row("ties", r.ties);
  row("mismatches", r.mismatches);
  row(" bvh right", r.bvh_right);
  row(" embree right", r.embree_right);
  row(" both right", r.both_right);
  row(" both wrong", r.both_wrong);
  std::fprintf(stderr, "  max rel t error: %.3g (agreeing), %.3g (bvh vs arbiter)\n",
               r.max_rel_t_error, r.max_rel_t_error_arbiter);
  std::fprintf(stderr, "  bvh wrong on %zu rays: %s%s%s\n", r.bvh_wrong(),
               r.bvh_wrong() ? "FAIL" : "pass", written.empty() ? "" : "; mismatches -> ",
               written.c_str());
}

int run_validate_rays(const ValidateRaysArgs& a) {
  if (a.rays.empty() == a.kind.empty())
    throw InputError("--rays/--kind", "give exactly one of --rays FILE or --kind K -n N");
  std::optional<RayKind> kind;
  if (!a.kind.empty()) {
    kind = parse_ray_kind(a.kind);
    if (!(a.n >= 1.0)) throw InputError("-n", "--kind needs -n with at least 1 ray");
    if (a.n > kMaxRays || a.n != std::floor(a.n))
      throw InputError("-n", "must be a whole number of rays up to 1e9");
  }
  if (!(a.brute_force_limit >= 0.0)) throw InputError("--brute-force-limit", "must be >= 0");
  check_output_directory(a.mismatches);
  BackendOptions bvh_opts = finish_backend_options(a.backend);
  bvh_opts.backend = "bvh";
  BackendOptions embree_opts = bvh_opts;
  embree_opts.backend = "embree";
  const Scene scene = load_scene(a.scene);
  std::vector<Ray> rays;
  if (!kind) rays = read_rays(a.rays);

  RayDiffOptions diff_opts;
  diff_opts.brute_force_limit = size_t(a.brute_force_limit);
  RayDiffResult r;
  std::string bvh_name, embree_name;
  run_with_threads(bvh_opts.threads, [&] {
    std::unique_ptr<Intersector> embree = make_intersector("embree", embree_opts);
    embree->build(scene);
    std::unique_ptr<Intersector> bvh = make_intersector("bvh", bvh_opts);
    bvh->build(scene);
    if (kind) rays = make_rays(scene, *kind, size_t(a.n), a.seed, embree.get());
    r = run_ray_diff(scene, rays, *bvh, *embree, a.occluded, diff_opts);
    bvh_name = bvh->info().name;
    embree_name = embree->info().name;
  });

  std::string written;
  if (r.mismatches > 0) {
    std::vector<Ray> bad;
    bad.reserve(r.mismatches);
    for (size_t i : r.mismatch_indices) bad.push_back(rays[i]);
    write_rays(a.mismatches, bad);
    written = a.mismatches;
  }
  const std::string source =
      kind ? std::string(to_string(*kind)) + ", seed " + std::to_string(a.seed) : a.rays;
  print_table(a, r, bvh_name, embree_name, source, written);
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
    j["bvh_config"] = bvh_name;
    j["embree_config"] = embree_name;
    j["kind"] = kind ? nlohmann::json(std::string(to_string(*kind))) : nlohmann::json(nullptr);
    j["rays_file"] = kind ? nlohmann::json(nullptr) : nlohmann::json(a.rays);
    j["triangles"] = scene.triangle_count();
    j["brute_force"] = r.brute_force;
    j["mismatches_file"] = written.empty() ? nlohmann::json(nullptr) : nlohmann::json(written);
    j["pass"] = r.bvh_wrong() == 0;
    std::cout << j.dump() << std::endl;
  }
  return r.bvh_wrong() == 0 ? 0 : 1;
}

}  // namespace

void add_validate_rays_command(CLI::App& validate, CommandState& state) {
  auto args = std::make_shared<ValidateRaysArgs>();
  CLI::App* cmd = validate.add_subcommand(
      "rays", "trace rays through bvh and embree; settle mismatches with an exact arbiter");
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
  add_backend_options(*cmd, args->backend, /*with_backend=*/false);
  cmd->callback([args, &state] { state.exit_code = run_validate_rays(*args); });
}

}  // namespace hprt::cli
