#include "backends/backend_option_parse.h"

#include <charconv>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/parallel.h"

namespace hprt {
namespace {

[[noreturn]] void bad(std::string_view key, const std::string& problem) {
  throw OptionError(std::string(key), problem);
}

// A whole number in [lo, hi], the whole text.
int parse_int(std::string_view key, std::string_view v, int lo, int hi) {
  int x = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
  if (ec != std::errc() || end != v.data() + v.size() || v.empty())
    bad(key, "expected a whole number, got '" + std::string(v) + "'");
  if (x < lo || x > hi)
    bad(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                 std::string(v));
  return x;
}

// A finite number in [lo, hi], the whole text.
float parse_float(std::string_view key, std::string_view v, float lo, float hi) {
  const std::string s(v);
  char* end = nullptr;
  const double x = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size()) bad(key, "expected a number, got '" + s + "'");
  if (!std::isfinite(x)) bad(key, "must be a finite number, got " + s);
  if (x < double(lo) || x > double(hi))
    bad(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + s);
  return float(x);
}

template <typename T>
T need(std::string_view key, std::string_view v, std::optional<T> parsed, const char* expected) {
  if (!parsed) bad(key, "expected " + std::string(expected) + ", got '" + std::string(v) + "'");
  return *parsed;
}

std::optional<bool> parse_on_off(std::string_view v) {
  if (v == "on") return true;
  if (v == "off") return false;
  return std::nullopt;
}

std::optional<UpdateStrategy> parse_update(std::string_view v) {
  if (v == "rebuild") return UpdateStrategy::kRebuild;
  if (v == "refit") return UpdateStrategy::kRefit;
  if (v == "adaptive") return UpdateStrategy::kAdaptive;
  if (v == "auto") return UpdateStrategy::kAuto;
  return std::nullopt;
}

std::optional<std::string> parse_quality(std::string_view v) {
  if (v == "low" || v == "medium" || v == "high" || v == "refit") return std::string(v);
  return std::nullopt;
}

}  // namespace

void set_backend_option(BackendOptions& o, std::string_view key, std::string_view v) {
  if (key == "threads") {
    o.threads = parse_int(key, v, 0, kMaxThreads);
  } else if (key == "builder") {
    o.build.builder =
        need(key, v, parse_builder(v), "sweep, presorted, binned, parallel or morton");
  } else if (key == "bins") {
    o.build.bins = parse_int(key, v, kMinBins, kMaxBins);
  } else if (key == "leaf_size") {
    o.build.max_leaf_size = parse_int(key, v, 1, kMaxLeafSize);
  } else if (key == "sah_traversal") {
    o.build.sah.traversal_cost = parse_float(key, v, 0.0f, 1.0e6f);
  } else if (key == "sah_intersection") {
    o.build.sah.intersection_cost = parse_float(key, v, 1.0e-6f, 1.0e6f);
  } else if (key == "sah_leaf_block") {
    o.build.sah.leaf_block = parse_int(key, v, 1, kMaxLeafBlock);
  } else if (key == "isect") {
    o.triangle_test = need(key, v, parse_triangle_test(v), "watertight or mt");
  } else if (key == "layout") {
    o.layout = need(key, v, parse_layout(v), "bvh2, bvh4 or bvh8");
  } else if (key == "quality") {
    o.embree_quality = need(key, v, parse_quality(v), "low, medium, high or refit");
  } else if (key == "robust") {
    o.embree_robust = need(key, v, parse_on_off(v), "on or off");
  } else if (key == "update") {
    o.update = need(key, v, parse_update(v), "auto, rebuild, refit or adaptive");
  } else if (key == "adaptive_factor") {
    o.adaptive_factor = parse_float(key, v, 1.0f, 100.0f);
  } else {
    bad(key,
        "unknown backend option (expected threads, builder, bins, leaf_size, sah_traversal, "
        "sah_intersection, sah_leaf_block, isect, layout, quality, robust, update or "
        "adaptive_factor)");
  }
}

}  // namespace hprt
