// Parallel binned SAH builder (Algorithm 5, oneTBB). Nodes with at least
// options.parallel_cutoff primitives bin in parallel (per-range bins merged
// with min/max and integer adds: exact) and partition in parallel (per-chunk
// counts, prefix sums, order-preserving scatter = std::stable_partition);
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
#include <utility>

#include "bvh/binned_subtree.h"
#include "bvh/builder_common.h"
#include "bvh/builders.h"

namespace hprt {

namespace {

constexpr size_t kChunk = 8192;  // fixed work unit: never depends on the thread count

// A node of the parallel top, or a sequentially built subtree below it.
struct Part {
  BuildNode node;
  std::unique_ptr<Part> left, right;
  std::vector<BuildNode> subtree;  // non-empty: this part is a finished subtree
  size_t total = 0;                // nodes in this part
};

struct BoundsPair {
  AABB b, c;
};

class ParallelBuilder {
 public:
  ParallelBuilder(const BuildOptions& o, BoxRef* refs, BoxRef* temp)
      : o_(o), refs_(refs), temp_(temp) {}

  BoundsPair bounds_of(size_t begin, size_t end) const {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(begin, end, kChunk), BoundsPair{},
        [&](const tbb::blocked_range<size_t>& r, BoundsPair acc) {
          const auto [b, c] = ref_bounds(refs_ + r.begin(), r.size());
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

  std::unique_ptr<Part> build(size_t begin, size_t end, int depth, const AABB& bounds,
                              const AABB& cbounds) {
    auto part = std::make_unique<Part>();
    const size_t n = end - begin;
    if (n < static_cast<size_t>(o_.parallel_cutoff)) {
      part->subtree.reserve(2 * n - 1);
      BinnedSubtreeBuilder seq(o_, refs_, temp_);
      seq.build(begin, end, depth, bounds, cbounds, part->subtree);
      part->total = part->subtree.size();
      return part;
    }
    const BinMapping m(cbounds, o_.bins);
    SplitKind kind = decide_before_binning(n, depth, o_.max_leaf_size, m);
    if (kind == SplitKind::kSah && leaf_before_binning(refs_ + begin, n, bounds.half_area(), o_))
      kind = SplitKind::kLeaf;
    BinnedSplit split;
    if (kind == SplitKind::kSah) {
      const Bins bins = parallel_bins(begin, end, m);
      std::vector<float> sa;
      std::vector<uint32_t> sc;
      split = find_binned_split(bins, m, o_.sah, bounds.half_area(), sa, sc);
      kind = decide_after_binning(split, n, bounds.half_area(), o_);
    }
    if (kind == SplitKind::kLeaf) {
      part->node = make_leaf(bounds, begin, n);
      part->total = 1;
      return part;
    }
    size_t mid;
    AABB lb, rb, lc, rc;
    if (kind == SplitKind::kSah) {
      mid = parallel_partition(begin, end, m, split.axis, split.cut, lc, rc);
      lb = split.left_bounds;
      rb = split.right_bounds;
    } else {  // object median of the (ascending) range, as in build_binned
      mid = begin + n / 2;
      BoundsPair l, r;
      tbb::parallel_invoke([&] { l = bounds_of(begin, mid); }, [&] { r = bounds_of(mid, end); });
      lb = l.b, lc = l.c, rb = r.b, rc = r.c;
    }
    part->node = make_inner(bounds);
    tbb::parallel_invoke([&] { part->left = build(begin, mid, depth + 1, lb, lc); },
                         [&] { part->right = build(mid, end, depth + 1, rb, rc); });
    part->total = 1 + part->left->total + part->right->total;
    return part;
  }

  // Writes `part` into out[offset, offset + part.total) in canonical preorder.
  static void place(const Part& part, size_t offset, BuildNode* out) {
    if (!part.subtree.empty()) {
      const uint32_t off = static_cast<uint32_t>(offset);
      for (size_t i = 0; i < part.subtree.size(); ++i) {
        BuildNode nd = part.subtree[i];
        if (!nd.is_leaf()) nd.right += off;
        out[offset + i] = nd;
      }
      return;
    }
    out[offset] = part.node;
    if (part.node.is_leaf()) return;
    const size_t right = offset + 1 + part.left->total;
    out[offset].right = static_cast<uint32_t>(right);
    tbb::parallel_invoke([&] { place(*part.left, offset + 1, out); },
                         [&] { place(*part.right, right, out); });
  }

 private:
  Bins parallel_bins(size_t begin, size_t end, const BinMapping& m) const {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(begin, end, kChunk), Bins(o_.bins),
        [&](const tbb::blocked_range<size_t>& r, Bins acc) {
          Bins spare(o_.bins);
          bin_refs(m, refs_ + r.begin(), r.size(), acc, spare);
          return acc;
        },
        [](Bins x, const Bins& y) {
          x.merge(y);
          return x;
        });
  }

  // Parallel stable partition of refs_[begin, end): per-chunk left counts,
  // exclusive prefix sums, order-preserving scatter into temp_, copy back.
  size_t parallel_partition(size_t begin, size_t end, const BinMapping& m, int axis, int cut,
                            AABB& lc, AABB& rc) {
    const size_t n = end - begin;
    const size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<size_t> lefts(chunks);
    std::vector<AABB> lcb(chunks), rcb(chunks);
    tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
      const size_t b = begin + c * kChunk, e = std::min(end, b + kChunk);
      size_t k = 0;
      for (size_t i = b; i < e; ++i) k += goes_left(m, axis, cut, refs_[i]) ? 1 : 0;
      lefts[c] = k;
    });
    std::vector<size_t> loff(chunks), roff(chunks);
    size_t nl = 0, nr = 0;
    for (size_t c = 0; c < chunks; ++c) {
      const size_t b = c * kChunk, e = std::min(n, b + kChunk);
      loff[c] = nl;
      roff[c] = nr;
      nl += lefts[c];
      nr += (e - b) - lefts[c];
    }
    tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
      const size_t b = begin + c * kChunk, e = std::min(end, b + kChunk);
      BoxRef* lw = temp_ + begin + loff[c];
      BoxRef* rw = temp_ + begin + nl + roff[c];
      VecBox l, r;
      for (size_t i = b; i < e; ++i) {
        const BoxRef& ref = refs_[i];
        if (goes_left(m, axis, cut, ref)) {
          *lw++ = ref;
          l.extend(ref.center());
        } else {
          *rw++ = ref;
          r.extend(ref.center());
        }
      }
      lcb[c] = l.aabb();
      rcb[c] = r.aabb();
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, kChunk),
                      [&](const tbb::blocked_range<size_t>& r) {
                        std::copy(temp_ + r.begin(), temp_ + r.end(), refs_ + r.begin());
                      });
    for (size_t c = 0; c < chunks; ++c) {
      lc.extend(lcb[c]);
      rc.extend(rcb[c]);
    }
    return begin + nl;
  }

  const BuildOptions& o_;
  BoxRef* refs_;
  BoxRef* temp_;
};

}  // namespace

BuildTree build_parallel(const PrimInfo& prims, const BuildOptions& options) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  const auto refs = std::make_unique_for_overwrite<BoxRef[]>(n);
  const auto temp = std::make_unique_for_overwrite<BoxRef[]>(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kChunk),
                    [&](const tbb::blocked_range<size_t>& r) {
                      fill_box_refs(prims, refs.get(), r.begin(), r.end());
                    });
  ParallelBuilder b(options, refs.get(), temp.get());
  const BoundsPair root = b.bounds_of(0, n);
  const std::unique_ptr<Part> top = b.build(0, n, 1, root.b, root.c);
  tree.nodes.resize(top->total);
  ParallelBuilder::place(*top, 0, tree.nodes.data());
  tree.prim_order.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kChunk),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i)
                        tree.prim_order[i] = refs[i].index();
                    });
  return tree;
}

}  // namespace hprt
