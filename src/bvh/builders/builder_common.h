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

#include "bvh/builders/build_tree.h"
#include "bvh/input/build_options.h"
#include "bvh/input/prim_info.h"
#include "core/error.h"

namespace hprt {

inline void validate_build_options(const BuildOptions& o) {
  if (o.bins < kMinBins || o.bins > kMaxBins)
    throw OptionError("bins", "must be between " + std::to_string(kMinBins) + " and " +
                                  std::to_string(kMaxBins) + ", got " + std::to_string(o.bins));
  if (o.max_leaf_size < 1 || o.max_leaf_size > kMaxLeafSize)
    throw OptionError("leaf_size", "must be between 1 and " + std::to_string(kMaxLeafSize) +
                                       ", got " + std::to_string(o.max_leaf_size));
  if (o.parallel_cutoff < 1) throw OptionError("parallel_cutoff", "must be at least 1");
  if (!(o.sah.traversal_cost >= 0.0f))
    throw OptionError("sah_traversal",
                      "must be at least 0, got " + std::to_string(o.sah.traversal_cost));
  if (!(o.sah.intersection_cost > 0.0f))
    throw OptionError("sah_intersection",
                      "must be above 0, got " + std::to_string(o.sah.intersection_cost));
  if (o.sah.leaf_block < 1 || o.sah.leaf_block > kMaxLeafBlock)
    throw OptionError("sah_leaf_block", "must be between 1 and " + std::to_string(kMaxLeafBlock) +
                                            ", got " + std::to_string(o.sah.leaf_block));
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
