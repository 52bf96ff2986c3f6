// The `hprt` command: builds the CLI11 app from the subcommands, runs it, and
// is the one place that turns errors into messages and exit codes
// (0 ok, 1 validation found mismatches, 2 bad input or usage).
#pragma once

namespace hprt::cli {

int run(int argc, char** argv);

}  // namespace hprt::cli
