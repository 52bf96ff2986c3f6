// The four builders of the report and a Morton builder, free functions all
// returning the same canonical BuildTree. `build_tree` dispatches on options.builder.
#pragma once

#include <functional>

#include "bvh/builders/build_tree.h"
#include "bvh/input/build_options.h"
#include "bvh/input/prim_info.h"
#include "core/tree_stats.h"

namespace hprt {

BuildTree build_sweep(const PrimInfo& prims, const BuildOptions& options);      // Algorithm 1
BuildTree build_presorted(const PrimInfo& prims, const BuildOptions& options);  // Algorithm 2
BuildTree build_binned(const PrimInfo& prims, const BuildOptions& options);     // Algorithm 3
BuildTree build_parallel(const PrimInfo& prims, const BuildOptions& options);   // Algorithm 5
// Not in the report: Morton codes, no SAH (builder_morton.cpp).
BuildTree build_morton(const PrimInfo& prims, const BuildOptions& options);

// build_binned and build_parallel calling `refs_filled` once their
// references hold every box: from then on they never read prims.bounds.
BuildTree build_binned(const PrimInfo& prims, const BuildOptions& options,
                       const std::function<void()>& refs_filled);
BuildTree build_parallel(const PrimInfo& prims, const BuildOptions& options,
                         const std::function<void()>& refs_filled);

// Throws std::invalid_argument when the builder reads centroids and `prims`
// was made without them, or when its boxes were released.
BuildTree build_tree(const PrimInfo& prims, const BuildOptions& options);
// build_tree, with prims.bounds released (PrimInfo::release_bounds) as soon
// as the builder is done with them: by the binned builders once their
// references hold the boxes, by the sweep builders after the build; kept for
// a Morton tree, whose layout reads many of them (builders.cpp).
BuildTree build_tree_releasing_bounds(PrimInfo& prims, const BuildOptions& options);

// Whether the builder reads PrimInfo::centroids (sweep, presorted); the
// binned, parallel and Morton builders take centres from the boxes.
bool builder_reads_centroids(BuilderKind builder);

// Statistics and the 64-bit tree hash of docs/ARCHITECTURE.md (tree_stats.cpp).
TreeStats compute_tree_stats(const BuildTree& tree, const PrimInfo& prims);
// Its sah_cost alone (the same bits), from the nodes only.
double build_tree_sah_cost(const BuildTree& tree);

}  // namespace hprt
