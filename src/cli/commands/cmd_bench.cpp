// `hprt bench build|trace|frontier`: parses options and calls the benchmarks
// of the hprt_bench library (bench/bench_*.h), which do the work.
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_build.h"
#include "bench/bench_trace.h"
#include "bench/frontier/bench_frontier.h"
#include "cli/bench_cli_options.h"
#include "cli/commands.h"

namespace hprt::cli {
namespace {

struct BuildCmd {
  BenchCliOptions common;
  std::vector<std::string> meshes;
  bool with_generated = false;
  bool with_10m = false;
  std::string backend;
};

void add_build(CLI::App& bench) {
  auto a = std::make_shared<BuildCmd>();
  CLI::App* cmd = bench.add_subcommand(
      "build", "BVH build time per builder and thread count, Embree beside (report Table 1)");
  cmd->add_option("mesh", a->meshes,
                  "mesh files (OBJ/PLY, .gz) or scenes; default: generated meshes at the "
                  "report's sizes (132,267 / 871,306 / 1,087,474 triangles)");
  cmd->add_flag("--generated", a->with_generated, "also run the generated meshes with MESH files");
  cmd->add_flag("--10m", a->with_10m, "also run a generated 10M-triangle mesh (slow)");
  cmd->add_option("--backend", a->backend,
                  "also time this backend's build() (rows backend:SPEC): bvh, embree or "
                  "plugin:PATH.so[:OPTIONS]")
      ->check(backend_spec_validator());
  add_bench_common_options(*cmd, a->common);
  cmd->callback([a] {
    bench::BuildBenchConfig c;
    c.common = finish_bench_options(a->common);
    c.meshes = a->meshes;
    c.with_generated = a->with_generated;
    c.with_10m = a->with_10m;
    c.backend = a->backend;
    emit_bench_report(bench::run_build_bench(c));
  });
}

struct TraceCmd {
  BenchCliOptions common;
  std::vector<std::string> scenes;
  size_t rays = 0;
  std::string layout = "bvh8";
  std::string backend = "bvh";
  std::vector<std::string> meshes;
  bool no_suite = false;
  size_t suite_tris = 0;
};

void add_trace(CLI::App& bench) {
  auto a = std::make_shared<TraceCmd>();
  CLI::App* cmd = bench.add_subcommand(
      "trace", "render time and Mrays/s per ray kind, bvh against embree (report Table 2)");
  cmd->add_option("scene", a->scenes,
                  "scene JSON or mesh files; default: data/scenes/single_13mm.json (one model) "
                  "and data/scenes/combo.json (five models)");
  cmd->add_option("--rays", a->rays, "rays per ray kind (default 1,000,000; --quick 20,000)");
  cmd->add_option("--layout", a->layout, "bvh traversal layout (binary, 4- or 8-wide nodes)")
      ->check(CLI::IsMember({"bvh2", "bvh4", "bvh8"}));
  cmd->add_option("--meshes", a->meshes,
                  "mesh files of the large-mesh suite (default: dragon.ply.gz, happy_buddha.obj, "
                  "lucy.obj, armadillo.obj, sponza.obj.gz under ../shared/data/meshes, each "
                  "skipped with a note when absent; --quick: none)");
  cmd->add_option("--suite-tris", a->suite_tris,
                  "triangles of the suite's generated bumpy sphere, soup and sliver sheet (default "
                  "1,000,000; --quick 20,000)");
  cmd->add_flag("--no-suite", a->no_suite, "skip the large-mesh suite");
  cmd->add_option("--backend", a->backend,
                  "the backend timed against Embree (bvh columns): bvh, embree or "
                  "plugin:PATH.so[:OPTIONS]")
      ->check(backend_spec_validator())
      ->capture_default_str();
  add_bench_common_options(*cmd, a->common);
  cmd->callback([a] {
    bench::TraceBenchConfig c;
    c.common = finish_bench_options(a->common);
    c.scenes = a->scenes;
    c.rays = a->rays;
    c.layout = *parse_layout(a->layout);
    c.backend = a->backend;
    c.suite = !a->no_suite;
    c.meshes = a->meshes;
    c.suite_tris = a->suite_tris;
    emit_bench_report(bench::run_trace_bench(c));
  });
}

struct FrontierCmd {
  BenchCliOptions common;
  std::string mesh;
  size_t hard_rays = 0;
  size_t trace_rays = 0;
  std::string backend;
};

void add_frontier(CLI::App& bench) {
  auto a = std::make_shared<FrontierCmd>();
  CLI::App* cmd = bench.add_subcommand(
      "frontier", "speed against error per configuration, Pareto front, PNG plot (gnuplot)");
  cmd->add_option("mesh", a->mesh,
                  "a mesh file, best closed (vertex/edge probes need it); default: a generated "
                  "80k-triangle sphere (--quick: 5k)");
  cmd->add_option("--hard-rays", a->hard_rays,
                  "rays per hard-case set (default 2,000; --quick 200)");
  cmd->add_option("--trace-rays", a->trace_rays,
                  "primary and random rays each for the speed (default 250,000; --quick 10,000)");
  cmd->add_option("--backend", a->backend,
                  "add this backend's row (bvh, embree or plugin:PATH.so[:OPTIONS])")
      ->check(backend_spec_validator());
  add_bench_common_options(*cmd, a->common);
  cmd->callback([a] {
    bench::FrontierBenchConfig c;
    c.common = finish_bench_options(a->common);
    c.mesh = a->mesh;
    c.hard_rays = a->hard_rays;
    c.trace_rays = a->trace_rays;
    c.backend = a->backend;
    emit_bench_report(bench::run_frontier_bench(c));
  });
}

}  // namespace

void add_bench_command(CLI::App& app, CommandState& /*state*/) {
  CLI::App* bench = app.add_subcommand(
      "bench", "benchmarks with Embree in the same run: Markdown tables, CSV/JSON, plots");
  bench->require_subcommand(1);
  add_build(*bench);
  add_trace(*bench);
  add_frontier(*bench);
}

}  // namespace hprt::cli
