// Binned SAH builder (Algorithm 3; Wald 2007): options.bins bins per axis over
// the node's centroid bounds, bins-1 cuts per axis from prefix/suffix sweeps,
// stable in-place partition. Sequential; build_parallel reproduces it exactly.
#include <algorithm>
#include <limits>
#include <memory>
#include <tuple>

#include "bvh/binned_subtree.h"
#include "bvh/builder_common.h"
#include "bvh/builders.h"

namespace hprt {

BinnedSubtreeBuilder::BinnedSubtreeBuilder(const BuildOptions& options, BoxRef* refs, BoxRef* temp)
    : options_(options), refs_(refs), temp_(temp), bins_(options.bins), spare_(options.bins) {}

void BinnedSubtreeBuilder::build(size_t begin, size_t end, int depth, const AABB& bounds,
                                 const AABB& centroid_bounds, std::vector<BuildNode>& out) {
  recurse(begin, end, depth, bounds, centroid_bounds, out.size(), out);
}

namespace {

// Stable partition of refs[begin, end) by the chosen cut; rights go through
// temp[begin, end) (disjoint ranges: parallel subtrees share the arrays).
// Branch-free: every ref is written to both sides and only one cursor moves.
// Returns the split index and the children's centroid bounds.
template <int A>
size_t partition_axis(const BinMapping& m, int cut, BoxRef* refs, BoxRef* temp, size_t begin,
                      size_t end, AABB& lc, AABB& rc) {
  const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
  const __m128 ninf = _mm_sub_ps(_mm_setzero_ps(), inf);
  __m128 llo = inf, lhi = ninf, rlo = inf, rhi = ninf;
  const __m128i vcut = _mm_set1_epi32(cut);
  size_t w = begin, t = begin;
  for (size_t i = begin; i < end; ++i) {
    const BoxRef r = refs[i];
    const __m128 c = r.center();
    // Every lane: bin(c[A]) > cut, i.e. the ref goes right.
    const __m128i gt = _mm_cmpgt_epi32(m.bins_of(c), vcut);
    const __m128i right_i = _mm_shuffle_epi32(gt, _MM_SHUFFLE(A, A, A, A));
    const __m128 right = _mm_castsi128_ps(right_i);
    refs[w] = r;
    temp[t] = r;
    const size_t is_right = static_cast<size_t>(_mm_cvtsi128_si32(right_i)) & 1;
    w += 1 - is_right;
    t += is_right;
    // The centre on its side, the empty value (inf / -inf) on the other.
    const __m128 cl = _mm_andnot_ps(right, c), cr = _mm_and_ps(right, c);
    llo = _mm_min_ps(llo, _mm_or_ps(cl, _mm_and_ps(right, inf)));
    lhi = _mm_max_ps(lhi, _mm_or_ps(cl, _mm_and_ps(right, ninf)));
    rlo = _mm_min_ps(rlo, _mm_or_ps(cr, _mm_andnot_ps(right, inf)));
    rhi = _mm_max_ps(rhi, _mm_or_ps(cr, _mm_andnot_ps(right, ninf)));
  }
  std::copy(temp + begin, temp + t, refs + w);
  lc = vec_to_aabb(llo, lhi);
  rc = vec_to_aabb(rlo, rhi);
  return w;
}

}  // namespace

void BinnedSubtreeBuilder::recurse(size_t begin, size_t end, int depth, const AABB& bounds,
                                   const AABB& cbounds, size_t base, std::vector<BuildNode>& out) {
  const size_t n = end - begin;
  const BinMapping m(cbounds, options_.bins);
  SplitKind kind = decide_before_binning(n, depth, options_.max_leaf_size, m);
  if (kind == SplitKind::kSah &&
      leaf_before_binning(refs_ + begin, n, bounds.half_area(), options_))
    kind = SplitKind::kLeaf;
  BinnedSplit split;
  if (kind == SplitKind::kSah && n <= kSmallNodeMax && n <= static_cast<size_t>(options_.bins)) {
    split = find_binned_split_small(refs_ + begin, n, m, options_.sah, bounds.half_area());
    kind = decide_after_binning(split, n, bounds.half_area(), options_);
  } else if (kind == SplitKind::kSah) {
    bins_.reset();
    bin_refs(m, refs_ + begin, n, bins_, spare_);
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
        mid = partition_axis<0>(m, split.cut, refs_, temp_, begin, end, lc, rc);
        break;
      case 1:
        mid = partition_axis<1>(m, split.cut, refs_, temp_, begin, end, lc, rc);
        break;
      default:
        mid = partition_axis<2>(m, split.cut, refs_, temp_, begin, end, lc, rc);
        break;
    }
    lb = split.left_bounds;
    rb = split.right_bounds;
  } else {  // object median of the (ascending) range
    mid = begin + n / 2;
    std::tie(lb, lc) = ref_bounds(refs_ + begin, mid - begin);
    std::tie(rb, rc) = ref_bounds(refs_ + mid, end - mid);
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
  const auto refs = std::make_unique_for_overwrite<BoxRef[]>(n);
  const auto temp = std::make_unique_for_overwrite<BoxRef[]>(n);
  fill_box_refs(prims, refs.get(), 0, n);
  const auto [bounds, cbounds] = ref_bounds(refs.get(), n);
  tree.nodes.reserve(2 * n - 1);
  BinnedSubtreeBuilder builder(options, refs.get(), temp.get());
  builder.build(0, n, 1, bounds, cbounds, tree.nodes);
  tree.prim_order.resize(n);
  for (size_t i = 0; i < n; ++i) tree.prim_order[i] = refs[i].index();
  return tree;
}

}  // namespace hprt
