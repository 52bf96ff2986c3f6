// The sequential binned-SAH recursion (Algorithm 3), shared by build_binned
// and by build_parallel below its cut-off, plus the node decision both use.
// Primitive ranges stay in ascending index order (stable partitions from the
// identity), so a leaf's primitives are ascending and the median fallback is
// simply the middle of the range.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvh/binning.h"
#include "bvh/build_options.h"
#include "bvh/build_tree.h"
#include "bvh/prim_info.h"
#include "bvh/sah.h"

namespace hprt {

enum class SplitKind { kLeaf, kSah, kMedian };

// Before binning: kSah means "bin and decide after".
inline SplitKind decide_before_binning(size_t n, int depth, int max_leaf_size,
                                       const BinMapping& m) {
  if (n <= 1) return SplitKind::kLeaf;
  if (must_split_median(depth, n, kMaxBuildDepth) || !m.any_usable())
    return n <= static_cast<size_t>(max_leaf_size) ? SplitKind::kLeaf : SplitKind::kMedian;
  return SplitKind::kSah;
}

inline SplitKind decide_after_binning(const BinnedSplit& s, size_t n, float parent_area,
                                      const BuildOptions& o) {
  if (sah_make_leaf(o.sah, o.max_leaf_size, parent_area, n, s.cost)) return SplitKind::kLeaf;
  return s.axis < 0 ? SplitKind::kMedian : SplitKind::kSah;
}

// True when the primitive with centroid c goes left of the chosen cut.
inline bool goes_left(const BinMapping& m, int axis, int cut, const Vec3f& c) {
  return m.bin(c[axis], axis) <= cut;
}

class BinnedSubtreeBuilder {
 public:
  // order/temp: the whole primitive order and a scratch array of equal size.
  BinnedSubtreeBuilder(const PrimInfo& prims, const BuildOptions& options, uint32_t* order,
                       uint32_t* temp);

  // Appends the subtree over order[begin, end) to `out` in canonical preorder,
  // with `right` links relative to out's start and leaf `first` absolute.
  void build(size_t begin, size_t end, int depth, const AABB& bounds, const AABB& centroid_bounds,
             std::vector<BuildNode>& out);

 private:
  void recurse(size_t begin, size_t end, int depth, const AABB& bounds, const AABB& cbounds,
               size_t base, std::vector<BuildNode>& out);

  const PrimInfo& prims_;
  const BuildOptions& options_;
  uint32_t* order_;
  uint32_t* temp_;
  Bins bins_;
  std::vector<float> scratch_area_;
  std::vector<uint32_t> scratch_count_;
};

}  // namespace hprt
