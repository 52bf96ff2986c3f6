#include "bvh/input/build_options.h"

namespace hprt {

std::string_view to_string(BuilderKind k) {
  switch (k) {
    case BuilderKind::kSweep:
      return "sweep";
    case BuilderKind::kPresorted:
      return "presorted";
    case BuilderKind::kBinned:
      return "binned";
    case BuilderKind::kParallel:
      return "parallel";
    case BuilderKind::kMorton:
      return "morton";
  }
  return "?";
}

std::optional<BuilderKind> parse_builder(std::string_view s) {
  if (s == "sweep") return BuilderKind::kSweep;
  if (s == "presorted") return BuilderKind::kPresorted;
  if (s == "binned") return BuilderKind::kBinned;
  if (s == "parallel") return BuilderKind::kParallel;
  if (s == "morton") return BuilderKind::kMorton;
  return std::nullopt;
}

std::string_view to_string(TriangleTestKind k) {
  return k == TriangleTestKind::kWatertight ? "watertight" : "mt";
}

std::optional<TriangleTestKind> parse_triangle_test(std::string_view s) {
  if (s == "watertight") return TriangleTestKind::kWatertight;
  if (s == "mt" || s == "moller") return TriangleTestKind::kMoller;
  return std::nullopt;
}

std::string_view to_string(BvhLayout k) {
  switch (k) {
    case BvhLayout::kBvh2:
      return "bvh2";
    case BvhLayout::kBvh4:
      return "bvh4";
    case BvhLayout::kBvh8:
      return "bvh8";
  }
  return "?";
}

std::optional<BvhLayout> parse_layout(std::string_view s) {
  if (s == "bvh2") return BvhLayout::kBvh2;
  if (s == "bvh4") return BvhLayout::kBvh4;
  if (s == "bvh8") return BvhLayout::kBvh8;
  return std::nullopt;
}

}  // namespace hprt
