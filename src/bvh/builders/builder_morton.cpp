// Morton builder (linear BVH, Lauterbach et al. 2009): the fast, lower-quality
// build for per-frame rebuilds of deforming scenes, what Embree's LOW quality
// does too. Each centroid is quantised to a 1024^3 grid over the centroid
// bounds and its 30-bit Morton code sorted (stable LSD radix, 3 passes of 10
// bits, parallel over fixed chunks: equal codes keep ascending indices). A
// node splits its sorted range where its highest differing code bit turns to
// 1 (binary search); where all its codes are equal, or the depth guard of
// sah.h says so, it splits at the middle: the object-median fallback of the
// other builders (the floor(n/2) smallest indices left when codes tie). A
// range of at most max_leaf_size primitives is a leaf. No SAH: the bins and
// SAH options are checked, not used. Ranges of at least parallel_cutoff
// primitives build their halves as parallel tasks, so the tree is the same
// for any thread count.
#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <memory>
#include <vector>

#include "bvh/builders/builder_common.h"
#include "bvh/builders/builders.h"
#include "bvh/memory/huge_buffer.h"
#include "bvh/split/sah.h"

namespace hprt {
namespace {

constexpr size_t kChunk = 16384;  // fixed work unit: never depends on the thread count
constexpr int kRadixBits = 10;
constexpr uint32_t kRadix = 1u << kRadixBits;
constexpr int kCodeShift = 32;  // key = code << 32 | PrimInfo index

// The 10 low bits of v spread to every third bit: one pdep where BMI2 is
// there and fast (Zen 1 and 2 run pdep in microcode, hundreds of cycles),
// a dozen dependent shifts and masks otherwise.
uint32_t spread_bits(uint32_t v) {
#if defined(__BMI2__) && !defined(__znver1__) && !defined(__znver2__)
  return _pdep_u32(v, 0x09249249u);
#else
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
#endif
}

// Grid cell 0..1023 of v along one axis; in double so that a tiny extent
// cannot overflow the scale. A flat axis maps to cell 0.
struct AxisQuantizer {
  double lo = 0.0, scale = 0.0;
  AxisQuantizer(float min, float max)
      : lo(min), scale(max > min ? double(kRadix) / (double(max) - double(min)) : 0.0) {}
  uint32_t cell(float v) const {
    const double f = (double(v) - lo) * scale;
    return static_cast<uint32_t>(std::clamp(f, 0.0, double(kRadix - 1)));  // no branch
  }
};

// One stable counting pass on the digit at `shift`: per-chunk histograms,
// prefix sums in (digit, chunk) order, per-chunk scatter.
void radix_pass(const uint64_t* src, uint64_t* dst, size_t n, int shift) {
  const size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<uint32_t> offsets(chunks * kRadix, 0);
  const auto digit = [shift](uint64_t key) { return uint32_t(key >> shift) & (kRadix - 1); };
  tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
    uint32_t* count = &offsets[c * kRadix];
    for (size_t i = c * kChunk, e = std::min(n, i + kChunk); i < e; ++i) ++count[digit(src[i])];
  });
  uint32_t sum = 0;
  for (uint32_t d = 0; d < kRadix; ++d)
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t k = offsets[c * kRadix + d];
      offsets[c * kRadix + d] = sum;
      sum += k;
    }
  tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
    uint32_t* next = &offsets[c * kRadix];
    for (size_t i = c * kChunk, e = std::min(n, i + kChunk); i < e; ++i)
      dst[next[digit(src[i])]++] = src[i];
  });
}

// Two parallel passes over the split structure, so each node is written once,
// straight into its place in the canonical preorder (no scratch array of
// nodes, whose fresh pages cost more than the nodes, and no copy): plan()
// splits the ranges of at least parallel_cutoff primitives as parallel tasks
// and, for each smaller range, finds its subtree's splits (no boxes), keeps
// them (4 bytes per inner node) and counts its nodes; place() then emits
// every small range's subtree at its offset from the kept splits, in
// parallel, and bounds the planned nodes above them from their children. The
// splits of a range depend only on the sorted codes and its depth, so the
// tree is the same whatever the thread count.
class MortonBuilder {
 public:
  struct Plan {
    size_t begin = 0, end = 0;
    size_t total = 0;                   // nodes of the subtree
    std::unique_ptr<Plan> left, right;  // none: emitted sequentially by place()
  };

  // `splits`: room for n entries; the subtree of a range [b, e) built
  // sequentially keeps its splits at splits[b, e).
  MortonBuilder(const BuildOptions& o, const uint64_t* keys, size_t n, const AABB* boxes,
                uint32_t* splits)
      : o_(o), keys_(keys), n_(n), boxes_(boxes), splits_(splits) {}

  std::unique_ptr<Plan> plan(size_t begin, size_t end, int depth) const {
    auto p = std::make_unique<Plan>();
    p->begin = begin;
    p->end = end;
    const size_t n = end - begin;
    if (n < static_cast<size_t>(o_.parallel_cutoff) || is_leaf(n)) {
      uint32_t* cursor = splits_ + begin;
      p->total = count(begin, end, depth, cursor);
      return p;
    }
    const size_t mid = split(begin, end, depth);
    tbb::parallel_invoke([&] { p->left = plan(begin, mid, depth + 1); },
                         [&] { p->right = plan(mid, end, depth + 1); });
    p->total = 1 + p->left->total + p->right->total;
    return p;
  }

  // Writes `p`'s subtree at out[offset, offset + p.total).
  void place(const Plan& p, size_t offset, BuildNode* out) const {
    if (!p.left) {
      size_t next = offset;
      const uint32_t* cursor = splits_ + p.begin;
      emit(p.begin, p.end, out, next, cursor);
      return;
    }
    const size_t right = offset + 1 + p.left->total;
    tbb::parallel_invoke([&] { place(*p.left, offset + 1, out); },
                         [&] { place(*p.right, right, out); });
    AABB bounds = out[offset + 1].bounds;
    bounds.extend(out[right].bounds);
    out[offset] = make_inner(bounds);
    out[offset].right = static_cast<uint32_t>(right);
  }

 private:
  bool is_leaf(size_t n) const { return n <= static_cast<size_t>(o_.max_leaf_size); }
  uint32_t code(size_t i) const { return uint32_t(keys_[i] >> kCodeShift); }
  const AABB& box(size_t i) const { return boxes_[uint32_t(keys_[i])]; }

  // Nodes of the subtree of [begin, end); its inner nodes' splits go to
  // cursor[0...] in preorder (fewer than end - begin of them).
  size_t count(size_t begin, size_t end, int depth, uint32_t*& cursor) const {
    if (is_leaf(end - begin)) return 1;
    const size_t mid = split(begin, end, depth);
    *cursor++ = static_cast<uint32_t>(mid);
    const size_t left = count(begin, mid, depth + 1, cursor);
    return 1 + left + count(mid, end, depth + 1, cursor);
  }

  // Sequential subtree of [begin, end) written in preorder at out[next...]
  // (right children are indices into `out`), its splits read from count()'s
  // record; returns its bounds.
  AABB emit(size_t begin, size_t end, BuildNode* out, size_t& next, const uint32_t*& cursor) const {
    const size_t self = next++;
    if (is_leaf(end - begin)) {
      AABB box;
      for (size_t i = begin; i < end; ++i) {
        // Leaves come in sorted order and read the boxes at random.
        if (i + kPrefetchAhead < n_)
          _mm_prefetch(reinterpret_cast<const char*>(&boxes_[uint32_t(keys_[i + kPrefetchAhead])]),
                       _MM_HINT_T0);
        box.extend(this->box(i));
      }
      out[self] = make_leaf(box, begin, end - begin);
      return box;
    }
    const size_t mid = *cursor++;
    AABB box = emit(begin, mid, out, next, cursor);
    const uint32_t right = static_cast<uint32_t>(next);
    box.extend(emit(mid, end, out, next, cursor));
    out[self] = make_inner(box);
    out[self].right = right;
    return box;
  }

  // Where [begin, end) (at least 2 primitives) splits.
  size_t split(size_t begin, size_t end, int depth) const {
    const uint32_t first = code(begin), last = code(end - 1);
    if (first == last || must_split_median(depth, end - begin, kMaxBuildDepth))
      return begin + (end - begin) / 2;
    // Above the highest differing bit all codes of the range agree, so that
    // bit is 0 then 1 along the sorted range.
    // Branch-free binary search for the first code with the bit set: code(lo)
    // has it clear, code(lo + n) set (or lo + n == end).
    const uint32_t bit = 1u << (31 - std::countl_zero(first ^ last));
    size_t lo = begin, n = end - begin;
    while (n > 1) {
      const size_t half = n / 2;
      lo += (code(lo + half) & bit) ? 0 : half;
      n -= half;
    }
    return lo + 1;
  }

  static constexpr size_t kPrefetchAhead = 16;
  const BuildOptions& o_;
  const uint64_t* keys_;  // sorted
  size_t n_;
  const AABB* boxes_;  // PrimInfo::bounds, indexed by a key's low 32 bits
  uint32_t* splits_;   // see the constructor
};

}  // namespace

BuildTree build_morton(const PrimInfo& prims, const BuildOptions& options) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  const AABB& cb = prims.centroid_bounds;
  const AxisQuantizer qx(cb.min.x, cb.max.x), qy(cb.min.y, cb.max.y), qz(cb.min.z, cb.max.z);
  const auto keys = make_huge_buffer<uint64_t>(n);
  const auto temp = make_huge_buffer<uint64_t>(n);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, n, kChunk), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
          const Vec3f c = prims.bounds[i].center();  // make_prim_info's centroid, bit for bit
          const uint32_t code = spread_bits(qx.cell(c.x)) << 2 | spread_bits(qy.cell(c.y)) << 1 |
                                spread_bits(qz.cell(c.z));
          keys[i] = uint64_t(code) << kCodeShift | i;
        }
      });
  // 3 passes: keys -> temp -> keys -> temp.
  radix_pass(keys.get(), temp.get(), n, kCodeShift);
  radix_pass(temp.get(), keys.get(), n, kCodeShift + kRadixBits);
  radix_pass(keys.get(), temp.get(), n, kCodeShift + 2 * kRadixBits);
  const uint64_t* sorted = temp.get();

  tree.prim_order.reserve(n);
  advise_huge_pages(tree.prim_order.data(), n * sizeof(uint32_t));
  tree.prim_order.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kChunk),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i)
                        tree.prim_order[i] = static_cast<uint32_t>(sorted[i]);
                    });
  const auto splits = make_huge_buffer<uint32_t>(n);
  const MortonBuilder builder(options, sorted, n, prims.bounds.data(), splits.get());
  const auto plan = builder.plan(0, n, 1);
  // First touched by the placing tasks (as place_parts does).
  tree.nodes.reserve(plan->total);
  advise_huge_pages(tree.nodes.data(), plan->total * sizeof(BuildNode));
  tree.nodes.resize(plan->total);
  builder.place(*plan, 0, tree.nodes.data());
  return tree;
}

}  // namespace hprt
