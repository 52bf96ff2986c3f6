#include "cli/app.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "cli/commands.h"
#include "core/error.h"
#include "io/files/atomic_file.h"

#ifndef HPRT_VERSION
#define HPRT_VERSION "0.1.0"
#endif

namespace hprt::cli {
namespace {

// The command line's name of a library option key: leaf_size -> --leaf-size,
// n -> -n (every key is spelt as its flag).
std::string option_flag(std::string key) {
  std::replace(key.begin(), key.end(), '_', '-');
  return (key.size() == 1 ? "-" : "--") + key;
}

}  // namespace

int run(int argc, char** argv) {
  install_output_cleanup_handlers();
  CLI::App app{"hprt: a parallel binned-SAH BVH ray tracer, diffed and timed against Embree"};
  app.set_version_flag("--version", std::string("hprt ") + HPRT_VERSION);
  app.require_subcommand(1);
  CommandState state;
  add_generate_command(app, state);
  add_build_command(app, state);
  add_rays_command(app, state);
  add_points_command(app, state);
  add_trace_command(app, state);
  add_query_command(app, state);
  add_render_command(app, state);
  add_validate_command(app, state);
  add_bench_command(app, state);
  add_bench_frames_command(*app.get_subcommand("bench"), state);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "hprt: error: %s (see hprt --help)\n", e.what());
    return 2;
  } catch (const OptionError& e) {
    std::fprintf(stderr, "hprt: error: %s: %s\n", option_flag(e.key()).c_str(), e.problem());
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "hprt: error: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "hprt: error: out of memory\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hprt: internal error: %s\n", e.what());
    return 3;
  }
  return state.exit_code;
}

}  // namespace hprt::cli
