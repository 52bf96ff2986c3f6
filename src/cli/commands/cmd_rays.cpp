// `hprt rays SCENE --kind K -n N [--seed S] -o OUT.rays`: writes a generated
// ray set (validators/ray_sets.h). Shadow, reflection and diffuse rays trace
// primary rays through a backend (default embree).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "backends/intersector.h"
#include "cli/commands.h"
#include "cli/malformed_warning.h"
#include "cli/output_path.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/rays/ray_file.h"
#include "io/scene/scene_reader.h"
#include "validators/ray_sets.h"

namespace hprt::cli {
namespace {

std::string format_count(double n) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", n);
  return buf;
}

struct RaysArgs {
  std::string scene;
  std::string kind;
  double n = 0;  // parsed as a number so 1e6 works; must be whole
  uint64_t seed = 1;
  std::string output;
  BackendCliOptions backend;
};

void run_rays(const RaysArgs& a) {
  if (!(a.n >= 1.0)) throw InputError("-n", "need at least 1 ray");
  if (a.n > double(kMaxRaySetSize))
    throw InputError("-n", "too many rays: " + format_count(a.n) + " (at most " +
                               std::to_string(kMaxRaySetSize) + ")");
  if (a.n != std::floor(a.n)) throw InputError("-n", "must be a whole number of rays");
  const RayKind kind = parse_ray_kind(a.kind);
  check_output_directory(a.output);
  const Scene scene = load_scene(a.scene);
  const BackendOptions options = finish_backend_options(a.backend);
  BuildInfo info;  // of the backend that traced the seeding rays, if any
  const std::vector<Ray> rays = run_with_threads(options.threads, [&] {
    std::unique_ptr<Intersector> backend;
    if (ray_kind_needs_backend(kind)) {
      backend = make_intersector(options.backend, options);
      backend->build(scene);
    }
    std::vector<Ray> made = make_rays(scene, kind, size_t(a.n), a.seed, backend.get());
    if (backend) info = backend->info();
    return made;
  });
  write_rays(a.output, rays);
  std::fprintf(stderr, "hprt rays: %zu %s rays (seed %llu) -> %s\n", rays.size(),
               std::string(to_string(kind)).c_str(), static_cast<unsigned long long>(a.seed),
               a.output.c_str());
  cli::warn_malformed("hprt rays", info.name, info.malformed_answers);
}

}  // namespace

void add_rays_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<RaysArgs>();
  args->backend.backend = "embree";
  CLI::App* cmd = app.add_subcommand("rays", "generate a ray set and write it as .rays");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("--kind", args->kind, "ray kind")
      ->required()
      ->check(CLI::IsMember(ray_kind_names()));
  cmd->add_option("-n", args->n, "number of rays (1 .. 1e9)")->required();
  cmd->add_option("--seed", args->seed, "random seed")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "output .rays file")->required();
  add_backend_options(*cmd, args->backend);
  cmd->callback([args] { run_rays(*args); });
}

}  // namespace hprt::cli
