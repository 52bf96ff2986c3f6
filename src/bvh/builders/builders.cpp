// build_tree: picks the builder named by options.builder. All builders share
// the canonical layout of build_tree.h; an input without valid primitives
// gives a tree with no nodes, a single primitive a single leaf.
#include "bvh/builders/builders.h"

#include <stdexcept>

namespace hprt {

bool builder_reads_centroids(BuilderKind builder) {
  return builder == BuilderKind::kSweep || builder == BuilderKind::kPresorted;
}

BuildTree build_tree(const PrimInfo& prims, const BuildOptions& options) {
  if (builder_reads_centroids(options.builder) && prims.centroids.size() != prims.size())
    throw std::invalid_argument("build_tree: this builder needs the primitives' centroids");
  if (prims.bounds.size() != prims.size())
    throw std::invalid_argument("build_tree: the primitives' boxes were released");
  switch (options.builder) {
    case BuilderKind::kSweep:
      return build_sweep(prims, options);
    case BuilderKind::kPresorted:
      return build_presorted(prims, options);
    case BuilderKind::kBinned:
      return build_binned(prims, options);
    case BuilderKind::kParallel:
      return build_parallel(prims, options);
    case BuilderKind::kMorton:
      return build_morton(prims, options);
  }
  return build_parallel(prims, options);
}

BuildTree build_tree_releasing_bounds(PrimInfo& prims, const BuildOptions& options) {
  const auto release = [&prims] { prims.release_bounds(); };
  if (options.builder == BuilderKind::kBinned) return build_binned(prims, options, release);
  if (options.builder == BuilderKind::kParallel) return build_parallel(prims, options, release);
  BuildTree tree = build_tree(prims, options);
  // A Morton tree's leaves are split into the wide nodes' free slots all
  // over (flatten_wide.cpp), each part's box from the primitive boxes; read
  // from the scene instead (three dependent loads each), they slow its
  // layout markedly. Its boxes stay.
  if (options.builder != BuilderKind::kMorton) release();
  return tree;
}

}  // namespace hprt
