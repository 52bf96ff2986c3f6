// The sequential binned-SAH recursion (Algorithm 3), shared by build_binned
// and by build_parallel below its cut-off, plus the node decision both use.
// Primitive ranges stay in ascending index order (stable partitions from the
// identity), so a leaf's primitives are ascending and the median fallback is
// simply the middle of the range.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvh/builders/build_tree.h"
#include "bvh/input/box_ref.h"
#include "bvh/input/build_options.h"
#include "bvh/split/binning.h"
#include "bvh/split/sah.h"

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

// True when a leaf costs no more than a lower bound of every split's cost,
// C_t SA(P) + C_i sum SA(prim) / leaf_block (a child's box holds its
// primitives' boxes, computed areas grow with the box, and a child of n
// primitives counts at least n / leaf_block blocks): binning would choose the
// leaf too. The margin covers the rounding of both sums, so the answer is
// always binning's.
inline bool leaf_before_binning(const BoxRef* refs, size_t n, float parent_area,
                                const BuildOptions& o) {
  if (n > static_cast<size_t>(o.max_leaf_size) || n > kSmallNodeMax) return false;
  float areas = 0.0f;
  for (size_t i = 0; i < n; ++i) areas += vec_half_area(refs[i].lo, refs[i].hi);
  const float bound = o.sah.traversal_cost * parent_area +
                      o.sah.intersection_cost * areas / static_cast<float>(o.sah.leaf_block);
  return sah_leaf_cost(o.sah, parent_area, n) <= bound * (1.0f - 1e-5f);
}

inline SplitKind decide_after_binning(const BinnedSplit& s, size_t n, float parent_area,
                                      const BuildOptions& o) {
  if (sah_make_leaf(o.sah, o.max_leaf_size, parent_area, n, s.cost)) return SplitKind::kLeaf;
  return s.axis < 0 ? SplitKind::kMedian : SplitKind::kSah;
}

// Leaf over refs[begin, end): its primitives' indices go to order[begin, end).
inline BuildNode make_ref_leaf(const AABB& bounds, const BoxRef* refs, uint32_t* order,
                               size_t begin, size_t end) {
  for (size_t i = begin; i < end; ++i) order[i] = refs[i].index();
  BuildNode n;
  n.bounds = bounds;
  n.first = static_cast<uint32_t>(begin);
  n.count = static_cast<uint32_t>(end - begin);
  return n;
}

class BinnedSubtreeBuilder {
 public:
  // refs: two reference arrays of the input's size; a range lives in one of
  // them (side 0 or 1) and its SAH children in the other. order: the tree's
  // prim_order, written by the leaves.
  BinnedSubtreeBuilder(const BuildOptions& options, BoxRef* refs0, BoxRef* refs1, uint32_t* order);

  // Appends the subtree over refs[side][begin, end) to `out` in canonical
  // preorder, with `right` links relative to out's start and leaf `first` absolute.
  void build(size_t begin, size_t end, int side, int depth, const AABB& bounds,
             const AABB& centroid_bounds, BuildNodes& out);

 private:
  void recurse(size_t begin, size_t end, int side, int depth, const AABB& bounds,
               const AABB& cbounds);

  const BuildOptions& options_;
  BoxRef* refs_[2];
  uint32_t* order_;
  BuildNodes* out_ = nullptr;
  size_t base_ = 0;
  Bins bins_, spare_;
  std::vector<float> scratch_area_;
  std::vector<uint32_t> scratch_count_;
};

}  // namespace hprt
