// What a BVH build is asked for: which builder, bins, leaf size, SAH constants.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace hprt {

// The report's four SAH builders, and a Morton (linear BVH) builder for fast
// per-frame rebuilds.
enum class BuilderKind { kSweep, kPresorted, kBinned, kParallel, kMorton };
enum class TriangleTestKind { kWatertight, kMoller };
// Traversal layout the build tree is flattened into: binary 32-byte nodes, or
// wide nodes of 4 or 8 children with SoA bounds (bvh/node_wide.h).
enum class BvhLayout { kBvh2, kBvh4, kBvh8 };

// SAH constants of the report's equation (1): cost = C_trav + sum over children
// of SA(child)/SA(parent) * C_isect * triangles(child). The defaults are those
// of Embree's builders (travCost 1, intCost 1) so trees are comparable.
struct SahParams {
  float traversal_cost = 1.0f;
  float intersection_cost = 1.0f;
};

struct BuildOptions {
  BuilderKind builder = BuilderKind::kParallel;
  int bins = 32;  // per axis; nodes under 20 * (bins - 4) primitives use fewer (bins_for)
  int max_leaf_size = 4;
  SahParams sah;
  // Below this many primitives the parallel builder works sequentially; a
  // primitive count, not a thread count, so the tree never depends on threads.
  int parallel_cutoff = 4096;
};

std::string_view to_string(BuilderKind k);
std::optional<BuilderKind> parse_builder(std::string_view s);
std::string_view to_string(TriangleTestKind k);
std::optional<TriangleTestKind> parse_triangle_test(std::string_view s);
std::string_view to_string(BvhLayout k);
std::optional<BvhLayout> parse_layout(std::string_view s);

}  // namespace hprt
