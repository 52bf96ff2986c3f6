// Parallel binned SAH builder (Algorithm 5, oneTBB). Nodes with at least
// options.parallel_cutoff primitives bin in parallel (per-range bins merged
// with min/max and integer adds: exact) and partition in parallel (per-chunk
// counts, prefix sums, order-preserving scatter = std::stable_partition, into the other of two
// reference arrays);
// their children are built as parallel tasks, each below the cut-off by the
// sequential binned code into its own node vector, and everything is stitched
// in canonical preorder from subtree sizes. Equals build_binned bit for bit
// for any thread count.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <utility>

#include "bvh/builders/binned_subtree.h"
#include "bvh/builders/builder_common.h"
#include "bvh/builders/builders.h"
#include "bvh/builders/parallel_parts.h"
#include "bvh/memory/huge_buffer.h"
#include "bvh/split/scatter_refs.h"

namespace hprt {

namespace {

constexpr size_t kChunk = 8192;  // fixed work unit: never depends on the thread count
// Tree size (nodes, as bytes) from which a build hands the freed heap pages
// of its subtrees back (trim_heap).
constexpr size_t kTrimHeapBytes = size_t{128} << 20;

struct BoundsPair {
  AABB b, c;
};

class ParallelBuilder {
 public:
  // refs: the two reference arrays (see BinnedSubtreeBuilder); order:
  // prim_order.
  ParallelBuilder(const BuildOptions& o, BoxRef* refs0, BoxRef* refs1, uint32_t* order)
      : o_(o), refs_{refs0, refs1}, order_(order) {}

  BoundsPair bounds_of(size_t begin, size_t end, int side) const {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(begin, end, kChunk), BoundsPair{},
        [&](const tbb::blocked_range<size_t>& r, BoundsPair acc) {
          const auto [b, c] = ref_bounds(refs_[side] + r.begin(), r.size());
          acc.b.extend(b);
          acc.c.extend(c);
          return acc;
        },
        [](BoundsPair x, const BoundsPair& y) {
          x.b.extend(y.b);
          x.c.extend(y.c);
          return x;
        });
  }

  std::unique_ptr<Part> build(size_t begin, size_t end, int side, int depth, const AABB& bounds,
                              const AABB& cbounds) {
    auto part = std::make_unique<Part>();
    const size_t n = end - begin;
    if (n < static_cast<size_t>(o_.parallel_cutoff)) {
      // Built into its own array, sized for the most nodes n primitives can
      // need (2n - 1), so it never grows. From malloc: recycled from build to
      // build only while glibc serves them from its heap (its mmap threshold
      // rises once large blocks are freed) and a large one-off build has not
      // handed the pages back (trim_heap, build_parallel), else fresh pages
      // each time (the Morton builder counts its subtrees first and writes
      // nodes in place).
      part->own.reserve(2 * n - 1);
      BinnedSubtreeBuilder seq(o_, refs_[0], refs_[1], order_);
      seq.build(begin, end, side, depth, bounds, cbounds, part->own);
      part->subtree = part->own;
      part->total = part->own.size();
      return part;
    }
    const BoxRef* src = refs_[side] + begin;
    const BinMapping m(cbounds, bins_for(n, o_.bins));
    SplitKind kind = decide_before_binning(n, depth, o_.max_leaf_size, m);
    if (kind == SplitKind::kSah && leaf_before_binning(src, n, bounds.half_area(), o_))
      kind = SplitKind::kLeaf;
    BinnedSplit split;
    Bins bins;
    std::vector<Bins> chunk_bins;
    if (kind == SplitKind::kSah) {
      bins = parallel_bins(src, n, m, chunk_bins);
      std::vector<float> sa;
      std::vector<uint32_t> sc;
      split = find_binned_split(bins, m, o_.sah, bounds.half_area(), sa, sc);
      kind = decide_after_binning(split, n, bounds.half_area(), o_);
    }
    if (kind == SplitKind::kLeaf) {
      part->node = make_ref_leaf(bounds, refs_[side], order_, begin, end);
      part->total = 1;
      return part;
    }
    size_t mid;
    int child_side = side;
    AABB lb, rb, lc, rc;
    if (kind == SplitKind::kSah) {
      mid = begin + split.left_count;
      child_side = 1 - side;
      parallel_partition(src, n, refs_[child_side] + begin, split, m, chunk_bins, lc, rc);
      chunk_bins = {};
      lb = split.left_bounds;
      rb = split.right_bounds;
    } else {  // object median of the (ascending) range, as in build_binned
      mid = begin + n / 2;
      BoundsPair l, r;
      tbb::parallel_invoke([&] { l = bounds_of(begin, mid, side); },
                           [&] { r = bounds_of(mid, end, side); });
      lb = l.b, lc = l.c, rb = r.b, rc = r.c;
    }
    part->node = make_inner(bounds);
    tbb::parallel_invoke([&] { part->left = build(begin, mid, child_side, depth + 1, lb, lc); },
                         [&] { part->right = build(mid, end, child_side, depth + 1, rb, rc); });
    part->total = 1 + part->left->total + part->right->total;
    return part;
  }

 private:
  // Bins of every kChunk-sized chunk of src[0, n) (kept: the partition takes
  // its per-chunk left counts from them) and their merge (exact in any order).
  static Bins parallel_bins(const BoxRef* src, size_t n, const BinMapping& m,
                            std::vector<Bins>& chunk_bins) {
    const size_t chunks = (n + kChunk - 1) / kChunk;
    chunk_bins.assign(chunks, Bins(m.bins));
    tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
      const size_t b = c * kChunk, e = std::min(n, b + kChunk);
      Bins spare(m.bins);
      bin_refs(m, src + b, e - b, chunk_bins[c], spare);
    });
    Bins all(m.bins);
    for (const Bins& cb : chunk_bins) all.merge(cb);
    return all;
  }

  // Parallel stable partition of src[0, n) into dst[0, n): per-chunk left
  // counts from the chunks' bins, exclusive prefix sums, order-preserving
  // scatter of every chunk.
  static void parallel_partition(const BoxRef* src, size_t n, BoxRef* dst, const BinnedSplit& s,
                                 const BinMapping& m, const std::vector<Bins>& chunk_bins, AABB& lc,
                                 AABB& rc) {
    const size_t chunks = chunk_bins.size();
    std::vector<size_t> lefts(chunks, 0), loff(chunks), roff(chunks);
    size_t nl = 0, nr = 0;
    for (size_t c = 0; c < chunks; ++c) {
      const size_t b = c * kChunk, e = std::min(n, b + kChunk);
      const uint32_t* cnt = &chunk_bins[c].counts[size_t(s.axis) * size_t(m.bins)];
      for (int k = 0; k <= s.cut; ++k) lefts[c] += cnt[k];
      loff[c] = nl;
      roff[c] = nr;
      nl += lefts[c];
      nr += (e - b) - lefts[c];
    }
    if (nl != s.left_count) throw std::logic_error("parallel build: partition disagrees");
    std::vector<VecBox> lcb(chunks), rcb(chunks);
    tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
      const size_t b = c * kChunk, e = std::min(n, b + kChunk);
      if (scatter_refs(s.axis, m, s.cut, src + b, e - b, dst + loff[c], dst + nl + roff[c], lcb[c],
                       rcb[c]) != lefts[c])
        throw std::logic_error("parallel build: partition disagrees");
    });
    for (size_t c = 0; c < chunks; ++c) {
      lc.extend(lcb[c].aabb());
      rc.extend(rcb[c].aabb());
    }
  }

  const BuildOptions& o_;
  BoxRef* refs_[2];
  uint32_t* order_;
};
}  // namespace

BuildTree build_parallel(const PrimInfo& prims, const BuildOptions& options,
                         const std::function<void()>& refs_filled) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  auto refs = make_huge_buffer<BoxRef>(n);
  auto temp = make_huge_buffer<BoxRef>(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kChunk),
                    [&](const tbb::blocked_range<size_t>& r) {
                      fill_box_refs(prims, refs.get(), r.begin(), r.end());
                    });
  if (refs_filled) refs_filled();
  tree.prim_order.reserve(n);
  advise_huge_pages(tree.prim_order.data(), n * sizeof(uint32_t));
  tree.prim_order.resize(n);
  ParallelBuilder b(options, refs.get(), temp.get(), tree.prim_order.data());
  const BoundsPair root = b.bounds_of(0, n, 0);
  std::unique_ptr<Part> top = b.build(0, n, 0, 1, root.b, root.c);
  // The references (64 bytes a primitive) go before the nodes are placed:
  // otherwise the build's peak memory holds them beside both copies of the
  // nodes (the parts' and the tree's).
  refs.reset();
  temp.reset();
  place_parts(*top, tree);
  // The subtrees' node arrays come from the C library's heap, which may keep
  // their pages once freed (on a 100M-triangle build, gigabytes: the layout
  // made next then peaks above them). A large one-off build gives them back;
  // rebuilds of an animation (the buffer cache retained) reuse them instead.
  const size_t part_bytes = top->total * sizeof(BuildNode);
  top.reset();
  if (part_bytes >= kTrimHeapBytes && !build_buffer_cache().retained()) trim_heap();
  return tree;
}

BuildTree build_parallel(const PrimInfo& prims, const BuildOptions& options) {
  return build_parallel(prims, options, {});
}

}  // namespace hprt
