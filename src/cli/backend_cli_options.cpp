// Backend options shared by every subcommand that traces rays.
#include <cmath>
#include <cstdlib>
#include <string>

#include "backends/backend_option_parse.h"
#include "backends/backend_spec.h"
#include "bvh/input/build_options.h"
#include "cli/commands.h"
#include "core/parallel.h"

namespace hprt::cli {

namespace {
// CLI::Range passes NaN (no comparison with it is true), so float options
// are checked for finiteness first.
const CLI::Validator kFinite(
    [](std::string& s) -> std::string {
      return std::isfinite(std::strtod(s.c_str(), nullptr)) ? std::string()
                                                            : "must be a finite number, got " + s;
    },
    "FINITE");
}  // namespace

const CLI::Validator& backend_spec_validator() {
  static const CLI::Validator v([](std::string& s) { return backend_spec_problem(s); },
                                "bvh|embree|plugin:PATH.so[:OPTIONS]");
  return v;
}

const CLI::Validator& non_negative_validator() {
  static const CLI::Validator v(
      [](std::string& s) -> std::string {
        char* end = nullptr;
        const double d = std::strtod(s.c_str(), &end);
        return end != s.c_str() && *end == '\0' && d >= 0.0 ? std::string()
                                                            : "must be a number >= 0, got " + s;
      },
      "NUMBER>=0");
  return v;
}

void add_reference_option(CLI::App& cmd, std::string& reference) {
  cmd.add_option("--reference", reference,
                 "the backend --backend is diffed against: bvh, embree or plugin:PATH.so[:OPTIONS]")
      ->check(backend_spec_validator())
      ->capture_default_str();
}

void add_threads_option(CLI::App& cmd, int& threads) {
  cmd.add_option("--threads", threads, "worker threads (0 = all hardware threads)")
      ->check(CLI::Range(0, kMaxThreads));
}

void add_backend_options(CLI::App& cmd, BackendCliOptions& o, bool with_backend) {
  if (with_backend)
    cmd.add_option("--backend", o.backend,
                   "intersector backend: bvh, embree, or plugin:PATH.so[:OPTIONS] (a library "
                   "implementing <hprt/plugin.h>; OPTIONS go to its create())")
        ->check(backend_spec_validator())
        ->capture_default_str();
  add_threads_option(cmd, o.options.threads);
  cmd.add_option("--builder", o.builder,
                 "bvh: builder (the report's four SAH builders, or morton: fast, no SAH)")
      ->check(CLI::IsMember({"sweep", "presorted", "binned", "parallel", "morton"}))
      ->capture_default_str();
  cmd.add_option("--bins", o.options.build.bins,
                 "bvh: bins per axis (binned, parallel; small nodes use fewer)")
      ->check(CLI::Range(kMinBins, kMaxBins))
      ->capture_default_str();
  cmd.add_option("--leaf-size", o.options.build.max_leaf_size, "bvh: most triangles in a leaf")
      ->check(CLI::Range(1, kMaxLeafSize))
      ->capture_default_str();
  cmd.add_option("--sah-traversal", o.options.build.sah.traversal_cost,
                 "bvh: SAH cost of an inner node (C_t of the report's equation (1))")
      ->check(kFinite)
      ->check(CLI::Range(0.0f, 1.0e6f))
      ->capture_default_str();
  cmd.add_option("--sah-intersection", o.options.build.sah.intersection_cost,
                 "bvh: SAH cost of one triangle test (C_i)")
      ->check(kFinite)
      ->check(CLI::Range(1.0e-6f, 1.0e6f))
      ->capture_default_str();
  cmd.add_option("--sah-leaf-block", o.options.build.sah.leaf_block,
                 "bvh: the SAH charges C_i per block of this many triangles (1: per triangle; "
                 "Embree's SAH: 4)")
      ->check(CLI::Range(1, kMaxLeafBlock))
      ->capture_default_str();
  cmd.add_option("--isect", o.isect, "bvh: ray/triangle test")
      ->check(CLI::IsMember({"watertight", "mt"}))
      ->capture_default_str();
  cmd.add_option("--layout", o.layout, "bvh: traversal layout (binary, 4- or 8-wide nodes)")
      ->check(CLI::IsMember({"bvh2", "bvh4", "bvh8"}))
      ->capture_default_str();
  cmd.add_option("--quality", o.quality, "embree: build quality")
      ->check(CLI::IsMember({"low", "medium", "high", "refit"}))
      ->capture_default_str();
  cmd.add_option("--robust", o.robust, "embree: RTC_SCENE_FLAG_ROBUST")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd.add_option("--update", o.update,
                 "deformable scenes: per-frame BVH update (auto: refit, or a Morton or SAH "
                 "rebuild chosen from measured build and query times)")
      ->check(CLI::IsMember({"auto", "rebuild", "refit", "adaptive"}))
      ->capture_default_str();
  cmd.add_option("--adaptive-factor", o.options.adaptive_factor,
                 "adaptive (and auto before any query was timed): rebuild when SAH cost exceeds "
                 "this factor x cost at last rebuild")
      ->check(kFinite)
      ->check(CLI::Range(1.0f, 100.0f))
      ->capture_default_str();
}

BackendOptions finish_backend_options(const BackendCliOptions& o) {
  BackendOptions r = o.options;
  r.backend = o.backend;
  r.build.builder = *parse_builder(o.builder);
  r.triangle_test = *parse_triangle_test(o.isect);
  r.layout = *parse_layout(o.layout);
  r.embree_quality = o.quality;
  r.embree_robust = o.robust == "on";
  set_backend_option(r, "update", o.update);
  return r;
}

}  // namespace hprt::cli
