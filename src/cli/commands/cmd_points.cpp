// `hprt points SCENE --kind random|near|hard -n N [--seed S] -o OUT.points`:
// writes a generated query point set (validators/point_sets.h) for `hprt
// query --kind inside|closest`.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/output_path.h"
#include "core/error.h"
#include "io/rays/ray_file.h"
#include "io/scene/scene_reader.h"
#include "validators/point_sets.h"

namespace hprt::cli {
namespace {

struct PointsArgs {
  std::string scene;
  std::string kind;
  double n = 0;  // parsed as a number so 1e6 works; must be whole
  uint64_t seed = 1;
  std::string output;
};

void run_points(const PointsArgs& a) {
  if (!(a.n >= 1.0) || a.n > double(kMaxPointSetSize) || a.n != std::floor(a.n))
    throw OptionError("n", "must be a whole number of points from 1 to 1e9");
  const PointKind kind = parse_point_kind(a.kind);
  check_output_directory(a.output);
  const Scene scene = load_scene(a.scene);
  const std::vector<Vec3f> points = make_points(scene, kind, size_t(a.n), a.seed, a.scene);
  write_points(a.output, points);
  std::fprintf(stderr, "hprt points: %zu %s points (seed %llu) -> %s\n", points.size(),
               std::string(to_string(kind)).c_str(), static_cast<unsigned long long>(a.seed),
               a.output.c_str());
}

}  // namespace

void add_points_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<PointsArgs>();
  CLI::App* cmd = app.add_subcommand("points", "generate query points and write them as .points");
  cmd->add_option("scene", args->scene, "scene JSON or mesh file (OBJ/PLY)")->required();
  cmd->add_option("--kind", args->kind,
                  "random: in the enlarged scene box; near: on the triangles within float "
                  "rounding; hard: on vertex planes, vertices and one ulp beside them")
      ->required()
      ->check(CLI::IsMember(point_kind_names()));
  cmd->add_option("-n", args->n, "number of points (1 .. 1e9)")->required();
  cmd->add_option("--seed", args->seed, "random seed")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "output .points file")->required();
  cmd->callback([args] { run_points(*args); });
}

}  // namespace hprt::cli
