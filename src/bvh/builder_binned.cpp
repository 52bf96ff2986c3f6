// Binned SAH builder (Algorithm 3; Wald 2007): options.bins bins per axis over
// the node's centroid bounds, bins-1 cuts per axis from prefix/suffix sweeps,
// stable in-place partition. Sequential; build_parallel reproduces it exactly.
#include <algorithm>
#include <numeric>
#include <tuple>

#include "bvh/binned_subtree.h"
#include "bvh/builder_common.h"
#include "bvh/builders.h"

namespace hprt {

BinnedSubtreeBuilder::BinnedSubtreeBuilder(const PrimInfo& prims, const BuildOptions& options,
                                           uint32_t* order, uint32_t* temp)
    : prims_(prims), options_(options), order_(order), temp_(temp), bins_(options.bins) {}

void BinnedSubtreeBuilder::build(size_t begin, size_t end, int depth, const AABB& bounds,
                                 const AABB& centroid_bounds, std::vector<BuildNode>& out) {
  recurse(begin, end, depth, bounds, centroid_bounds, out.size(), out);
}

namespace {

// Stable partition of order[begin, end) by the chosen cut; rights go through
// temp[begin, end) (disjoint ranges: parallel subtrees share the arrays).
// Returns the split index and the children's centroid bounds.
template <int A>
size_t partition_axis(const PrimInfo& prims, const BinMapping& m, int cut, uint32_t* order,
                      uint32_t* temp, size_t begin, size_t end, AABB& lc, AABB& rc) {
  const Vec3f* cen = prims.centroids.data();
  size_t w = begin, t = begin;
  for (size_t i = begin; i < end; ++i) {
    const uint32_t id = order[i];
    const Vec3f& c = cen[id];
    const float v = A == 0 ? c.x : (A == 1 ? c.y : c.z);
    if (m.bin(v, A) <= cut) {
      order[w++] = id;
      lc.extend(c);
    } else {
      temp[t++] = id;
      rc.extend(c);
    }
  }
  std::copy(temp + begin, temp + t, order + w);
  return w;
}

}  // namespace

void BinnedSubtreeBuilder::recurse(size_t begin, size_t end, int depth, const AABB& bounds,
                                   const AABB& cbounds, size_t base, std::vector<BuildNode>& out) {
  const size_t n = end - begin;
  const BinMapping m(cbounds, options_.bins);
  SplitKind kind = decide_before_binning(n, depth, options_.max_leaf_size, m);
  BinnedSplit split;
  if (kind == SplitKind::kSah && n <= kSmallNodeMax && n <= static_cast<size_t>(options_.bins)) {
    split = find_binned_split_small(prims_.bounds.data(), prims_.centroids.data(), order_ + begin,
                                    n, m, options_.sah, bounds.half_area());
    kind = decide_after_binning(split, n, bounds.half_area(), options_);
  } else if (kind == SplitKind::kSah) {
    bins_.reset();
    const AABB* bx = prims_.bounds.data();
    const Vec3f* cen = prims_.centroids.data();
    for (size_t i = begin; i < end; ++i) {
      const uint32_t id = order_[i];
      bins_.add(m, bx[id], cen[id]);
    }
    split = find_binned_split(bins_, m, options_.sah, bounds.half_area(), scratch_area_,
                              scratch_count_);
    kind = decide_after_binning(split, n, bounds.half_area(), options_);
  }
  if (kind == SplitKind::kLeaf) {
    out.push_back(make_leaf(bounds, begin, n));
    return;
  }
  size_t mid;
  AABB lb, rb, lc, rc;
  if (kind == SplitKind::kSah) {
    switch (split.axis) {
      case 0:
        mid = partition_axis<0>(prims_, m, split.cut, order_, temp_, begin, end, lc, rc);
        break;
      case 1:
        mid = partition_axis<1>(prims_, m, split.cut, order_, temp_, begin, end, lc, rc);
        break;
      default:
        mid = partition_axis<2>(prims_, m, split.cut, order_, temp_, begin, end, lc, rc);
        break;
    }
    lb = split.left_bounds;
    rb = split.right_bounds;
  } else {  // object median of the (ascending) range
    mid = begin + n / 2;
    std::tie(lb, lc) = range_bounds(prims_, order_ + begin, mid - begin);
    std::tie(rb, rc) = range_bounds(prims_, order_ + mid, end - mid);
  }
  const size_t me = out.size();
  out.push_back(make_inner(bounds));
  recurse(begin, mid, depth + 1, lb, lc, base, out);
  out[me].right = static_cast<uint32_t>(out.size() - base);
  recurse(mid, end, depth + 1, rb, rc, base, out);
}

BuildTree build_binned(const PrimInfo& prims, const BuildOptions& options) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  tree.prim_order.resize(n);
  std::iota(tree.prim_order.begin(), tree.prim_order.end(), 0u);
  std::vector<uint32_t> temp(n);
  const auto [bounds, cbounds] = range_bounds(prims, tree.prim_order.data(), n);
  tree.nodes.reserve(2 * n - 1);
  BinnedSubtreeBuilder builder(prims, options, tree.prim_order.data(), temp.data());
  builder.build(0, n, 1, bounds, cbounds, tree.nodes);
  return tree;
}

}  // namespace hprt
