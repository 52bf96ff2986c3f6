// TEMPORARY: registrations for subcommands not written yet. Whoever implements
// a subcommand deletes its function here. This file must be empty of
// functions (and then deleted) before the work is resolved.
#include "cli/commands.h"

namespace hprt::cli {

void add_generate_command(CLI::App&, CommandState&) {}
void add_build_command(CLI::App&, CommandState&) {}
void add_rays_command(CLI::App&, CommandState&) {}
void add_trace_command(CLI::App&, CommandState&) {}
void add_render_command(CLI::App&, CommandState&) {}
void add_validate_command(CLI::App&, CommandState&) {}
void add_validate_rays_command(CLI::App&, CommandState&) {}
void add_validate_image_command(CLI::App&, CommandState&) {}
void add_bench_command(CLI::App&, CommandState&) {}

}  // namespace hprt::cli
