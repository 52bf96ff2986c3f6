// `hprt generate KIND [--tris N] [--seed S] [--from MESH] -o OUT.ply`: writes a
// procedural mesh (io/mesh/generate_mesh.h) as binary little-endian PLY, atomically.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/output_path.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "io/files/file_bytes.h"
#include "io/mesh/generate_mesh.h"
#include "io/mesh/ply_writer.h"

namespace hprt::cli {
namespace {

struct GenerateArgs {
  std::string kind;
  long long tris = 20000;
  uint64_t seed = 1;
  std::string from;
  std::string output;
};

void run_generate(const GenerateArgs& a) {
  if (a.tris < 1)
    throw InputError("--tris", "need at least 1 triangle, got " + std::to_string(a.tris));
  if (a.kind == "subdivide" && a.from.empty())
    throw InputError("--from", "'subdivide' needs an input mesh (--from MESH)");
  // Binary PLY, uncompressed: any other name would be read back as another format.
  if (has_gz_extension(a.output) || mesh_extension(a.output) != ".ply")
    throw InputError(a.output, "generate writes binary PLY: name the output .ply");
  check_output_directory(a.output);
  GenerateSpec spec;
  spec.kind = a.kind;
  spec.tris = size_t(a.tris);
  spec.seed = a.seed;
  spec.from = a.from;
  const auto t0 = Clock::now();
  const TriangleMesh mesh = generate_mesh(spec);
  const double generate_ms = ms_since(t0);
  const auto t1 = Clock::now();
  write_ply(mesh, a.output);
  const double write_ms = ms_since(t1);
  std::fprintf(stderr,
               "hprt generate: %s, %zu triangles, %zu vertices, %.1f ms (write %.1f ms) -> %s\n",
               a.kind.c_str(), mesh.triangle_count(), mesh.vertex_count(), generate_ms, write_ms,
               a.output.c_str());
}

}  // namespace

void add_generate_command(CLI::App& app, CommandState& /*state*/) {
  auto args = std::make_shared<GenerateArgs>();
  CLI::App* cmd = app.add_subcommand("generate", "write a procedural mesh as binary PLY");
  // The kinds listed in the help are the checker's set, generator_kinds().
  cmd->add_option("kind", args->kind, "procedural mesh kind, or subdivide (needs --from)")
      ->required()
      ->check(CLI::IsMember(generator_kinds()));
  cmd->add_option("--tris", args->tris, "target triangle count (1 .. 200M)")->capture_default_str();
  cmd->add_option("--seed", args->seed, "random seed (bumpy, soup, slivers, sheet, terrain)")
      ->capture_default_str();
  cmd->add_option("--from", args->from, "input mesh for subdivide (OBJ/PLY)");
  cmd->add_option("-o,--output", args->output, "output .ply file")->required();
  cmd->callback([args] { run_generate(*args); });
}

}  // namespace hprt::cli
