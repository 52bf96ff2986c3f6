// A backend named on the command line, in the public API or in a bench:
// "bvh", "embree" or "plugin:PATH[:OPTIONS]" (a shared library implementing
// include/hprt/plugin.h; OPTIONS go verbatim to its create()).
#pragma once

#include <string>
#include <string_view>

namespace hprt {

struct BackendSpec {
  enum class Kind { kBvh, kEmbree, kPlugin } kind = Kind::kBvh;
  std::string plugin_path;     // kPlugin
  std::string plugin_options;  // kPlugin: text after the second colon, "" if none
};

// Throws OptionError("backend", ...) for anything else (an empty plugin path too).
BackendSpec parse_backend_spec(std::string_view spec);

// The spec's problem, or "" when it parses (for CLI validators).
std::string backend_spec_problem(std::string_view spec);

}  // namespace hprt
