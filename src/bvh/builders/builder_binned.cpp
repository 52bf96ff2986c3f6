// Binned SAH builder (Algorithm 3; Wald 2007): per axis, bins_for(n) (at most
// options.bins) bins over the node's centroid bounds, bins-1 cuts from
// prefix/suffix sweeps, stable partition between two reference arrays.
// Sequential; build_parallel reproduces it exactly.
#include <algorithm>
#include <memory>
#include <stdexcept>
#include <tuple>

#include "bvh/builders/binned_subtree.h"
#include "bvh/builders/builder_common.h"
#include "bvh/builders/builders.h"
#include "bvh/memory/huge_buffer.h"
#include "bvh/split/scatter_refs.h"

namespace hprt {

BinnedSubtreeBuilder::BinnedSubtreeBuilder(const BuildOptions& options, BoxRef* refs0,
                                           BoxRef* refs1, uint32_t* order)
    : options_(options),
      refs_{refs0, refs1},
      order_(order),
      bins_(options.bins),
      spare_(options.bins) {}

void BinnedSubtreeBuilder::build(size_t begin, size_t end, int side, int depth, const AABB& bounds,
                                 const AABB& centroid_bounds, BuildNodes& out) {
  out_ = &out;
  base_ = out.size();
  recurse(begin, end, side, depth, bounds, centroid_bounds);
}

void BinnedSubtreeBuilder::recurse(size_t begin, size_t end, int side, int depth,
                                   const AABB& bounds, const AABB& cbounds) {
  const size_t n = end - begin;
  const BoxRef* src = refs_[side] + begin;
  const BinMapping m(cbounds, bins_for(n, options_.bins));
  SplitKind kind = decide_before_binning(n, depth, options_.max_leaf_size, m);
  if (kind == SplitKind::kSah && leaf_before_binning(src, n, bounds.half_area(), options_))
    kind = SplitKind::kLeaf;
  BinnedSplit split;
  if (kind == SplitKind::kSah && n <= kSmallNodeMax && n <= static_cast<size_t>(m.bins)) {
    split = find_binned_split_small(src, n, m, options_.sah, bounds.half_area());
    kind = decide_after_binning(split, n, bounds.half_area(), options_);
  } else if (kind == SplitKind::kSah) {
    bin_refs(m, src, n, bins_, spare_);
    split = find_binned_split(bins_, m, options_.sah, bounds.half_area(), scratch_area_,
                              scratch_count_);
    kind = decide_after_binning(split, n, bounds.half_area(), options_);
  }
  if (kind == SplitKind::kLeaf) {
    out_->push_back(make_ref_leaf(bounds, refs_[side], order_, begin, end));
    return;
  }
  size_t mid;
  int child_side = side;
  AABB lb, rb, lc, rc;
  if (kind == SplitKind::kSah) {
    mid = begin + split.left_count;
    child_side = 1 - side;
    BoxRef* dst = refs_[child_side];
    VecBox l, r;
    const size_t nl = scatter_refs(split.axis, m, split.cut, src, n, dst + begin, dst + mid, l, r);
    if (nl != split.left_count) throw std::logic_error("binned build: partition disagrees");
    lc = l.aabb();
    rc = r.aabb();
    lb = split.left_bounds;
    rb = split.right_bounds;
  } else {  // object median of the (ascending) range
    mid = begin + n / 2;
    std::tie(lb, lc) = ref_bounds(src, mid - begin);
    std::tie(rb, rc) = ref_bounds(src + (mid - begin), end - mid);
  }
  const size_t me = out_->size();
  out_->push_back(make_inner(bounds));
  recurse(begin, mid, child_side, depth + 1, lb, lc);
  (*out_)[me].right = static_cast<uint32_t>(out_->size() - base_);
  recurse(mid, end, child_side, depth + 1, rb, rc);
}

BuildTree build_binned(const PrimInfo& prims, const BuildOptions& options,
                       const std::function<void()>& refs_filled) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  const auto refs = make_huge_buffer<BoxRef>(n);
  const auto temp = make_huge_buffer<BoxRef>(n);
  fill_box_refs(prims, refs.get(), 0, n);
  if (refs_filled) refs_filled();
  const auto [bounds, cbounds] = ref_bounds(refs.get(), n);
  tree.prim_order.reserve(n);
  advise_huge_pages(tree.prim_order.data(), n * sizeof(uint32_t));
  tree.prim_order.resize(n);
  tree.nodes.reserve(2 * n - 1);
  advise_huge_pages(tree.nodes.data(), (2 * n - 1) * sizeof(BuildNode));
  BinnedSubtreeBuilder builder(options, refs.get(), temp.get(), tree.prim_order.data());
  builder.build(0, n, 0, 1, bounds, cbounds, tree.nodes);
  return tree;
}

BuildTree build_binned(const PrimInfo& prims, const BuildOptions& options) {
  return build_binned(prims, options, {});
}

}  // namespace hprt
