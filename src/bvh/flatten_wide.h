// Build tree -> wide traversal layout (WideBvh<N>): each wide node takes a
// binary inner node and opens, greedily, the child with the largest surface
// area until it has N children or only leaves (Embree's BVH4/8 builders
// collapse the same way: "Embree", SIGGRAPH 2014, Sec. 3.2). Leaves keep the
// binary tree's leaf ranges and the triangles their leaf order, so the wide
// and the binary layouts of one build trace the same triangles.
#pragma once

#include "bvh/build_tree.h"
#include "bvh/prim_info.h"
#include "bvh/wide_bvh.h"
#include "core/scene.h"

namespace hprt {

// `tree` must index `prims`, and `prims` must come from `scene`. An empty tree
// gives an empty WideBvh. Throws std::invalid_argument on a malformed tree.
template <int N>
WideBvh<N> flatten_wide(const BuildTree& tree, const PrimInfo& prims, const Scene& scene);

extern template WideBvh<4> flatten_wide<4>(const BuildTree&, const PrimInfo&, const Scene&);
extern template WideBvh<8> flatten_wide<8>(const BuildTree&, const PrimInfo&, const Scene&);

}  // namespace hprt
