#include "backends/backend_spec.h"

#include "core/error.h"

namespace hprt {

namespace {
constexpr std::string_view kPluginPrefix = "plugin:";
}

BackendSpec parse_backend_spec(std::string_view spec) {
  BackendSpec s;
  if (spec == "bvh") return s;
  if (spec == "embree") {
    s.kind = BackendSpec::Kind::kEmbree;
    return s;
  }
  if (spec.starts_with(kPluginPrefix)) {
    std::string_view rest = spec.substr(kPluginPrefix.size());
    const size_t colon = rest.find(':');
    s.kind = BackendSpec::Kind::kPlugin;
    s.plugin_path = std::string(rest.substr(0, colon));
    if (colon != std::string_view::npos) s.plugin_options = std::string(rest.substr(colon + 1));
    if (s.plugin_path.empty())
      throw OptionError(
          "backend",
          "'" + std::string(spec) + "' names no plugin file (expected plugin:PATH.so[:OPTIONS])");
    return s;
  }
  throw OptionError("backend", "unknown backend '" + std::string(spec) +
                                   "' (expected bvh, embree or plugin:PATH.so[:OPTIONS])");
}

std::string backend_spec_problem(std::string_view spec) {
  try {
    parse_backend_spec(spec);
    return {};
  } catch (const OptionError& e) {
    return e.problem();
  }
}

}  // namespace hprt
