// Each subcommand registers itself on the app; its callback does the work and
// stores its exit code (0 or 1) in `exit_code`. Bad input throws InputError.
#pragma once

#include <CLI/CLI.hpp>

#include "backends/intersector.h"

namespace hprt::cli {

struct CommandState {
  int exit_code = 0;
};

void add_generate_command(CLI::App& app, CommandState& state);
void add_build_command(CLI::App& app, CommandState& state);
void add_rays_command(CLI::App& app, CommandState& state);
void add_points_command(CLI::App& app, CommandState& state);
void add_trace_command(CLI::App& app, CommandState& state);
void add_query_command(CLI::App& app, CommandState& state);  // "query" count|all|inside|closest
void add_render_command(CLI::App& app, CommandState& state);
void add_validate_command(CLI::App& app, CommandState& state);  // "validate" + its two below
void add_validate_rays_command(CLI::App& validate, CommandState& state);
void add_validate_image_command(CLI::App& validate, CommandState& state);
void add_validate_query_command(CLI::App& validate, CommandState& state);
void add_bench_command(CLI::App& app, CommandState& state);  // "bench" build|trace|frontier
void add_bench_frames_command(CLI::App& bench, CommandState& state);  // "bench frames"

// --backend, --threads and every backend option (--builder, --bins,
// --leaf-size, --isect, --layout, --quality, --robust, --update, --adaptive-factor).
// Values are checked at parse time; finish_backend_options() converts them.
struct BackendCliOptions {
  std::string backend = "bvh";
  std::string builder = "parallel";
  std::string isect = "watertight";
  std::string layout = "bvh8";
  std::string quality = "medium";
  std::string robust = "off";
  std::string update = "auto";
  BackendOptions options;
};
void add_backend_options(CLI::App& cmd, BackendCliOptions& o, bool with_backend = true);
BackendOptions finish_backend_options(const BackendCliOptions& o);

// Checks a --backend/--reference value: bvh, embree or plugin:PATH.so[:OPTIONS].
const CLI::Validator& backend_spec_validator();
// A number >= 0, inf included, NaN not (CLI::NonNegativeNumber's message
// prints DBL_MAX in full).
const CLI::Validator& non_negative_validator();
// The validators' --reference (the backend --backend is diffed against).
void add_reference_option(CLI::App& cmd, std::string& reference);

// --threads alone (for commands without a backend choice).
void add_threads_option(CLI::App& cmd, int& threads);

}  // namespace hprt::cli
