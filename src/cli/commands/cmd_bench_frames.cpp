// `hprt bench frames [SCENE|MESH] [--frames N] [--tris N] [--adaptive-factor F]
// [--threads T] [--repeat R] [--quick] [--out DIR]`: CLI wiring of the
// deformable-scene benchmark (bench/bench_frames.h does the work).
#include <memory>
#include <string>

#include "bench/bench_frames.h"
#include "cli/bench_cli_options.h"
#include "cli/commands.h"

namespace hprt::cli {
namespace {

struct FramesCmd {
  BenchCliOptions common;
  std::string input;
  int frames = 0;
  size_t tris = 0;
  float adaptive_factor = 0.0f;
  std::string backend;
};

}  // namespace

void add_bench_frames_command(CLI::App& bench, CommandState& /*state*/) {
  auto a = std::make_shared<FramesCmd>();
  CLI::App* cmd = bench.add_subcommand(
      "frames",
      "deformable scenes: per-frame update + render, bvh rebuild/refit/adaptive against "
      "Embree's dynamic scene (refit and low quality)");
  cmd->add_option("input", a->input,
                  "scene JSON (its own animation) or mesh file (wave and explode); default: a "
                  "generated torus of --tris triangles");
  cmd->add_option("--frames", a->frames,
                  "frames timed after the initial build (default 10; "
                  "--quick 3)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--tris", a->tris,
                  "triangles of the generated input (default 1,000,000; --quick 20,000)")
      ->check(CLI::Range(size_t{1}, size_t{200'000'000}));
  cmd->add_option("--adaptive-factor", a->adaptive_factor,
                  "bvh adaptive: rebuild when the SAH cost exceeds this x the cost at the last "
                  "rebuild (default 1.3)")
      ->check(CLI::Range(1.0f, 100.0f));
  cmd->add_option("--backend", a->backend,
                  "add a row for this backend (bvh, embree or plugin:PATH.so[:OPTIONS]) with its "
                  "own update()")
      ->check(backend_spec_validator());
  add_bench_common_options(*cmd, a->common);
  cmd->callback([a] {
    bench::FramesBenchConfig c;
    c.common = finish_bench_options(a->common);
    c.input = a->input;
    c.frames = a->frames;
    c.tris = a->tris;
    c.adaptive_factor = a->adaptive_factor;
    c.backend = a->backend;
    emit_bench_report(bench::run_frames_bench(c));
  });
}

}  // namespace hprt::cli
