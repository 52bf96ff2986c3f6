// Build tree -> wide traversal layout (WideBvh<N>): the binary inner nodes
// are split into wide nodes and nodes opened into their wide parent's slots
// so that the wide nodes' total surface area is least (a dynamic program over
// the tree, see flatten_wide.cpp). Leaves keep the binary tree's leaf ranges
// and the triangles their leaf order, so the wide and the binary layouts of
// one build trace the same triangles.
#pragma once

#include "bvh/builders/build_tree.h"
#include "bvh/input/prim_info.h"
#include "bvh/layout/wide_bvh.h"
#include "core/scene.h"

namespace hprt {

// `tree` must index `prims`, and `prims` must come from `scene`. An empty tree
// gives an empty WideBvh. Throws std::invalid_argument on a malformed tree.
// `arrays`: the triangle test arrays to keep (LeafTriangles).
template <int N>
WideBvh<N> flatten_wide(const BuildTree& tree, const PrimInfo& prims, const Scene& scene,
                        TriangleArrays arrays = TriangleArrays::kBoth);

// The node pass alone: nodes, collapsed and root; `triangles` left empty, for
// gather_leaf_triangles(tree, prims, scene, arrays) (bvh/layout/flatten_bvh2.h) to fill,
// which may run at the same time (both only read `tree`, `prims` and `scene`).
// `prims` must come from `scene`, and may have released its boxes
// (PrimInfo::box then reads them from the scene).
template <int N>
WideBvh<N> flatten_wide_nodes(const BuildTree& tree, const PrimInfo& prims, const Scene& scene);

extern template WideBvh<4> flatten_wide_nodes<4>(const BuildTree&, const PrimInfo&, const Scene&);
extern template WideBvh<8> flatten_wide_nodes<8>(const BuildTree&, const PrimInfo&, const Scene&);
extern template WideBvh<4> flatten_wide<4>(const BuildTree&, const PrimInfo&, const Scene&,
                                           TriangleArrays);
extern template WideBvh<8> flatten_wide<8>(const BuildTree&, const PrimInfo&, const Scene&,
                                           TriangleArrays);

}  // namespace hprt
