// TEMPORARY: registrations for subcommands not written yet. Whoever implements
// a subcommand deletes its function here. This file must be empty of
// functions (and then deleted) before the work is resolved.
#include "cli/commands.h"

namespace hprt::cli {

void add_bench_command(CLI::App&, CommandState&) {}

}  // namespace hprt::cli
