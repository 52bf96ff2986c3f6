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
#include <numeric>
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
  ParallelBuilder(const PrimInfo& prims, const BuildOptions& o, uint32_t* order, uint32_t* temp)
      : prims_(prims), o_(o), order_(order), temp_(temp) {}

  BoundsPair bounds_of(size_t begin, size_t end) const {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(begin, end, kChunk), BoundsPair{},
        [&](const tbb::blocked_range<size_t>& r, BoundsPair acc) {
          const auto [b, c] = range_bounds(prims_, order_ + r.begin(), r.size());
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
      BinnedSubtreeBuilder seq(prims_, o_, order_, temp_);
      seq.build(begin, end, depth, bounds, cbounds, part->subtree);
      part->total = part->subtree.size();
      return part;
    }
    const BinMapping m(cbounds, o_.bins);
    SplitKind kind = decide_before_binning(n, depth, o_.max_leaf_size, m);
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
    const AABB* bx = prims_.bounds.data();
    const Vec3f* cen = prims_.centroids.data();
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(begin, end, kChunk), Bins(o_.bins),
        [&](const tbb::blocked_range<size_t>& r, Bins acc) {
          for (size_t i = r.begin(); i < r.end(); ++i) {
            const uint32_t id = order_[i];
            acc.add(m, bx[id], cen[id]);
          }
          return acc;
        },
        [](Bins x, const Bins& y) {
          x.merge(y);
          return x;
        });
  }

  // Parallel stable partition of order_[begin, end): per-chunk left counts,
  // exclusive prefix sums, order-preserving scatter into temp_, copy back.
  size_t parallel_partition(size_t begin, size_t end, const BinMapping& m, int axis, int cut,
                            AABB& lc, AABB& rc) {
    const size_t n = end - begin;
    const size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<size_t> lefts(chunks);
    std::vector<AABB> lcb(chunks), rcb(chunks);
    const Vec3f* cen = prims_.centroids.data();
    tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
      const size_t b = begin + c * kChunk, e = std::min(end, b + kChunk);
      size_t k = 0;
      for (size_t i = b; i < e; ++i) k += goes_left(m, axis, cut, cen[order_[i]]) ? 1 : 0;
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
      uint32_t* lw = temp_ + begin + loff[c];
      uint32_t* rw = temp_ + begin + nl + roff[c];
      AABB l, r;
      for (size_t i = b; i < e; ++i) {
        const uint32_t id = order_[i];
        const Vec3f& cc = cen[id];
        if (goes_left(m, axis, cut, cc)) {
          *lw++ = id;
          l.extend(cc);
        } else {
          *rw++ = id;
          r.extend(cc);
        }
      }
      lcb[c] = l;
      rcb[c] = r;
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, kChunk),
                      [&](const tbb::blocked_range<size_t>& r) {
                        std::copy(temp_ + r.begin(), temp_ + r.end(), order_ + r.begin());
                      });
    for (size_t c = 0; c < chunks; ++c) {
      lc.extend(lcb[c]);
      rc.extend(rcb[c]);
    }
    return begin + nl;
  }

  const PrimInfo& prims_;
  const BuildOptions& o_;
  uint32_t* order_;
  uint32_t* temp_;
};

}  // namespace

BuildTree build_parallel(const PrimInfo& prims, const BuildOptions& options) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  tree.prim_order.resize(n);
  std::vector<uint32_t> temp(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kChunk),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i)
                        tree.prim_order[i] = static_cast<uint32_t>(i);
                    });
  ParallelBuilder b(prims, options, tree.prim_order.data(), temp.data());
  const BoundsPair root = b.bounds_of(0, n);
  const std::unique_ptr<Part> top = b.build(0, n, 1, root.b, root.c);
  tree.nodes.resize(top->total);
  ParallelBuilder::place(*top, 0, tree.nodes.data());
  return tree;
}

}  // namespace hprt
