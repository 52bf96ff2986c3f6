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
// wide nodes of 4 or 8 children with SoA bounds (bvh/layout/node_wide.h).
enum class BvhLayout { kBvh2, kBvh4, kBvh8 };

// SAH constants of the report's equation (1): cost = C_trav + sum over children
// of SA(child)/SA(parent) * C_isect * triangles(child). Defaults 2 and 1: our
// leaf test checks up to 4 triangles in one lane test (leaf_intersect.h), so
// a triangle costs less than a node test (Embree's BVH8 triangle builder
// charges travCost 1 per node and intCost 1 per block of 4 triangles). Not
// higher: from 2.5 up a large triangle is kept in a leaf with small ones
// (leaf 4 A against split (C_trav + 1) A), and shadow rays leaving a
// 2-triangle floor (single_13mm.json) then test that leaf's 4 triangles
// instead of missing the floor's flat box.
// leaf_block: C_isect is charged per block of this many triangles (a leaf
// of n costs ceil(n / leaf_block) blocks), as Embree's SAH charges blocks of
// 4; 1 is the report's per-triangle cost. Blocks suit a leaf test that checks
// several triangles at once, and with a larger leaf size they keep meshes of
// overlapping boxes (slivers) in fewer, fuller leaves.
// Reported SAH costs are normalised to 1 and 1 whatever the build used
// (core/tree_stats.h).
struct SahParams {
  float traversal_cost = 2.0f;
  float intersection_cost = 1.0f;
  int leaf_block = 1;
};

// Limits of BuildOptions' fields. A traversal leaf reference holds its
// triangle count in 8 bits (NodeRef), hence the leaf size.
inline constexpr int kMinBins = 2;
inline constexpr int kMaxBins = 1024;
inline constexpr int kMaxLeafSize = 255;
inline constexpr int kMaxLeafBlock = 64;

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
