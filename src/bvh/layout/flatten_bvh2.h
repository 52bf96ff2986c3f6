// Build tree -> traversal layout (Bvh2): sibling pairs stored adjacently in
// depth-first order of their parents, triangles copied into leaf order with
// their precomputed test data (pbrt: BVHBuildNode -> LinearBVHNode).
#pragma once

#include "bvh/builders/build_tree.h"
#include "bvh/input/prim_info.h"
#include "bvh/layout/bvh2.h"
#include "core/scene.h"

namespace hprt {

// `tree` must index `prims`, and `prims` must come from `scene`. An empty tree
// (no valid triangle) gives an empty Bvh2. Throws std::invalid_argument on
// a malformed tree (a child index out of range, a leaf range past prim_order).
// `arrays`: the triangle test arrays to keep (LeafTriangles).
Bvh2 flatten(const BuildTree& tree, const PrimInfo& prims, const Scene& scene,
             TriangleArrays arrays = TriangleArrays::kBoth);

// The node pass alone (`triangles` left empty), for gather_leaf_triangles to
// fill, which may run at the same time (both only read `tree` and `prims`).
Bvh2 flatten_nodes(const BuildTree& tree, const PrimInfo& prims);

// The triangle pass of every layout: prim_order's triangles copied into leaf
// order with their test data (the `arrays` of verts, edges) and input refs,
// in parallel. prim_order's indices must be in range of `prims` (builders
// guarantee it).
LeafTriangles gather_leaf_triangles(const BuildTree& tree, const PrimInfo& prims,
                                    const Scene& scene,
                                    TriangleArrays arrays = TriangleArrays::kBoth);
// The same into `out`, whose arrays are reused where they have the size
// already (a rebuild over the same triangles writes the last build's storage).
void gather_leaf_triangles(const BuildTree& tree, const PrimInfo& prims, const Scene& scene,
                           TriangleArrays arrays, LeafTriangles& out);

}  // namespace hprt
