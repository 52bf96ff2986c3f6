// Refit of the traversal layout for deformable scenes: the topology of the
// last build is kept, the leaf-order triangle data is re-gathered from the
// scene's moved vertices and every node box is recomputed bottom-up from its
// children (leaves: from their triangles). Parallel (oneTBB task recursion at
// the top of the tree, sequential below), deterministic, allocation-free.
#pragma once

#include "bvh/layout/bvh2.h"
#include "bvh/memory/build_array.h"
#include "core/scene.h"

namespace hprt {

struct RefitResult {
  // False when a triangle of the tree is no longer valid (non-finite or zero
  // area, TriangleMesh::triangle_valid): the refitted tree must not be used,
  // rebuild instead. Its boxes and triangle data are then partly updated.
  bool valid = true;
  double sah_cost = 0.0;  // of the refitted tree, normalised as bvh2_sah_cost
};

// Which leaf-order triangle arrays a refit rewrites: those the layout holds
// (LeafTriangles::holds; refit throws std::invalid_argument for one it does
// not). Rewriting only the one the triangle test reads halves the triangle
// data written; the other, if held, is then stale and must not be read.
using RefitTriangles = TriangleArrays;

// The vertex indices of every leaf-order triangle (mesh.triangles[primID]
// copied next to the leaf order), made once after a build: a refit then
// reads them sequentially instead of chasing refs into the meshes' index
// arrays in random order.
struct RefitIndex {
  BuildArray<Vec3u> triangles;  // one per leaf-order triangle
};
RefitIndex make_refit_index(const Bvh2& bvh, const Scene& scene);
RefitIndex make_refit_index(const LeafTriangles& triangles, const Scene& scene);
// The same into `out`, its array reused where it has the size already.
void make_refit_index(const LeafTriangles& triangles, const Scene& scene, RefitIndex& out);

// `bvh` must have been built (flatten) over `scene` with the same meshes and
// triangle indices; only positions may differ. `index`, when given, must be
// make_refit_index of this bvh (else the indices are read through refs).
// Runs in the caller's task arena (run_with_threads). An empty bvh stays
// empty (cost 0).
RefitResult refit(Bvh2& bvh, const Scene& scene, RefitTriangles triangles = RefitTriangles::kBoth,
                  const RefitIndex* index = nullptr);

// The normalised SAH cost of docs/ARCHITECTURE.md over the flat layout, exactly as
// compute_tree_stats sums it over a BuildTree: inner nodes cost 1, leaves
// their triangle count, each weighted by SA(node) / SA(root) (half areas in
// float, sums in double; weight 1 when the root's area is 0). The sum runs in
// a different order than compute_tree_stats', so the two agree to rounding
// (relative ~1e-15), not bit for bit. 0 for an empty bvh.
double bvh2_sah_cost(const Bvh2& bvh);

}  // namespace hprt
