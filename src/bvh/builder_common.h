// Pieces every builder shares (internal to src/bvh): option checks, range
// bounds, and the node decision rule with its object-median fallback.
//
// Fallback (all builders alike): when a node must split but has no usable SAH
// split (all centroids coincide) or is too close to kMaxBuildDepth, its
// floor(n/2) primitives with the smallest indices go left, the rest right.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bvh/build_options.h"
#include "bvh/build_tree.h"
#include "bvh/prim_info.h"
#include "core/error.h"

namespace hprt {

inline void validate_build_options(const BuildOptions& o) {
  if (o.bins < 2 || o.bins > 1024)
    throw InputError("--bins", "must be between 2 and 1024, got " + std::to_string(o.bins));
  // A traversal leaf reference holds its count in 8 bits (NodeRef).
  if (o.max_leaf_size < 1 || o.max_leaf_size > 255)
    throw InputError("--leaf-size",
                     "must be between 1 and 255, got " + std::to_string(o.max_leaf_size));
  if (o.parallel_cutoff < 1) throw InputError("parallel_cutoff", "must be at least 1");
  if (!(o.sah.traversal_cost >= 0.0f) || !(o.sah.intersection_cost > 0.0f))
    throw InputError("SAH constants", "traversal cost must be >= 0 and intersection cost > 0");
}

// Union of boxes and of centroids of prims ids[0, n).
inline std::pair<AABB, AABB> range_bounds(const PrimInfo& prims, const uint32_t* ids, size_t n) {
  AABB b, c;
  for (size_t i = 0; i < n; ++i) {
    b.extend(prims.bounds[ids[i]]);
    c.extend(prims.centroids[ids[i]]);
  }
  return {b, c};
}

inline bool any_centroid_extent(const AABB& cb) {
  return cb.max.x > cb.min.x || cb.max.y > cb.min.y || cb.max.z > cb.min.z;
}

inline BuildNode make_leaf(const AABB& bounds, size_t first, size_t count) {
  BuildNode n;
  n.bounds = bounds;
  n.first = static_cast<uint32_t>(first);
  n.count = static_cast<uint32_t>(count);
  return n;
}

inline BuildNode make_inner(const AABB& bounds) {
  BuildNode n;
  n.bounds = bounds;
  return n;
}

}  // namespace hprt
