// Tests of the SAH cost functions (sah.h) and the binning helpers (binning.h).
#include <gtest/gtest.h>

#include <bit>
#include <iterator>
#include <vector>

#include "bvh/split/binning.h"
#include "bvh/split/sah.h"

namespace hprt {
namespace {

TEST(Sah, CostsFollowEquationOne) {
  SahParams p;
  p.traversal_cost = 2.0f;
  p.intersection_cost = 3.0f;
  // Scaled by SA(P) = 10: leaf = 3 * 4 * 10, split = 2*10 + 3*(4*1 + 6*3).
  EXPECT_FLOAT_EQ(sah_leaf_cost(p, 10.0f, 4), 120.0f);
  EXPECT_FLOAT_EQ(sah_split_cost(p, 10.0f, 4.0f, 1, 6.0f, 3), 20.0f + 3.0f * 22.0f);
}

TEST(Sah, LeafBlocksCountWholeBlocks) {
  SahParams p;
  p.traversal_cost = 1.0f;
  p.intersection_cost = 2.0f;
  p.leaf_block = 4;
  EXPECT_FLOAT_EQ(sah_units(p, 1), 1.0f);
  EXPECT_FLOAT_EQ(sah_units(p, 4), 1.0f);
  EXPECT_FLOAT_EQ(sah_units(p, 5), 2.0f);
  EXPECT_FLOAT_EQ(sah_units(p, 16), 4.0f);
  // Scaled by SA(P) = 10: leaf of 6 = 2 * 2 blocks * 10; split 1*10 + 2*(4*1 + 6*3 blocks).
  EXPECT_FLOAT_EQ(sah_leaf_cost(p, 10.0f, 6), 40.0f);
  EXPECT_FLOAT_EQ(sah_split_cost(p, 10.0f, 4.0f, 3, 6.0f, 9), 10.0f + 2.0f * (4.0f + 18.0f));
  // Per triangle (the report's cost) when the block is 1.
  p.leaf_block = 1;
  EXPECT_FLOAT_EQ(sah_leaf_cost(p, 10.0f, 6), 120.0f);
  // A leaf of 8 beats splitting it into two halves of the same area with
  // blocks of 4 (2 blocks either way, plus the node), not per triangle.
  p.traversal_cost = 1.0f;
  p.intersection_cost = 1.0f;
  p.leaf_block = 4;
  EXPECT_TRUE(sah_make_leaf(p, 8, 1.0f, 8, sah_split_cost(p, 1.0f, 0.8f, 4, 0.8f, 4)));
  p.leaf_block = 1;
  EXPECT_FALSE(sah_make_leaf(p, 8, 1.0f, 8, sah_split_cost(p, 1.0f, 0.8f, 4, 0.8f, 4)));
}

TEST(Sah, LeafRule) {
  const SahParams p;                                     // 1, 1
  EXPECT_TRUE(sah_make_leaf(p, 4, 1.0f, 1, 0.0f));       // one primitive: always a leaf
  EXPECT_FALSE(sah_make_leaf(p, 4, 1.0f, 5, kNoSplit));  // over the limit: never
  EXPECT_TRUE(sah_make_leaf(p, 4, 1.0f, 4, 4.0f));       // equal cost: leaf
  EXPECT_FALSE(sah_make_leaf(p, 4, 1.0f, 4, 3.9f));      // split cheaper
  EXPECT_TRUE(sah_make_leaf(p, 4, 1.0f, 3, kNoSplit));   // no split at all
}

TEST(Sah, DepthGuard) {
  EXPECT_EQ(ceil_log2(1), 0);
  EXPECT_EQ(ceil_log2(2), 1);
  EXPECT_EQ(ceil_log2(5), 3);
  EXPECT_EQ(ceil_log2(1024), 10);
  EXPECT_FALSE(must_split_median(1, 1000000, 64));
  EXPECT_TRUE(must_split_median(54, 1024, 64));
  EXPECT_FALSE(must_split_median(53, 1024, 64));
}

TEST(Binning, MappingCoversAllBins) {
  const AABB cb({0, 0, 0}, {1, 2, 0});
  const BinMapping m(cb, 8);
  EXPECT_TRUE(m.usable[0]);
  EXPECT_TRUE(m.usable[1]);
  EXPECT_FALSE(m.usable[2]);  // zero extent: skipped
  EXPECT_EQ(m.bin(0.0f, 0), 0);
  EXPECT_EQ(m.bin(1.0f, 0), 7);
  EXPECT_EQ(m.bin(2.0f, 1), 7);
  EXPECT_EQ(m.bin(0.49f, 0), 3);
  EXPECT_EQ(m.bin(0.51f, 0), 4);
  EXPECT_EQ(m.bin(-5.0f, 0), 0);  // clamped
  EXPECT_EQ(m.bin(9.0f, 0), 7);
  EXPECT_FALSE(BinMapping(AABB({1, 1, 1}, {1, 1, 1}), 8).any_usable());
}

TEST(Binning, FindsTheObviousSplitAndBreaksTiesByAxis) {
  // Two unit boxes far apart on x and on y alike (same geometry on both axes):
  // the cut must separate them, on axis 0 (lowest axis wins ties).
  const AABB a({0, 0, 0}, {1, 1, 1}), b({9, 9, 0}, {10, 10, 1});
  AABB cb;
  cb.extend(a.center());
  cb.extend(b.center());
  const BinMapping m(cb, 16);
  Bins bins(16);
  bins.add(m, a, a.center());
  bins.add(m, b, b.center());
  std::vector<float> sa;
  std::vector<uint32_t> sc;
  AABB parent = a;
  parent.extend(b);
  const BinnedSplit s = find_binned_split(bins, m, SahParams{}, parent.half_area(), sa, sc);
  EXPECT_EQ(s.axis, 0);
  EXPECT_EQ(s.cut, 0);  // lowest cut among the equal-cost ones
  EXPECT_EQ(s.left_count, 1u);
  EXPECT_EQ(s.right_count, 1u);
  EXPECT_EQ(s.left_bounds, a);
  EXPECT_EQ(s.right_bounds, b);
  EXPECT_FLOAT_EQ(s.cost, sah_split_cost(SahParams{}, parent.half_area(), 3.0f, 1, 3.0f, 1));
}

TEST(Binning, MergeIsExactInAnyOrder) {
  const BinMapping m(AABB({0, 0, 0}, {1, 1, 1}), 4);
  Bins x(4), y(4), z(4), all(4);
  for (int i = 0; i < 30; ++i) {
    const float f = float(i) / 29.0f;
    const AABB box({f, f * f, 1 - f}, {f + 0.1f, f * f + 0.3f, 1.2f - f});
    const Vec3f c = box.center();
    (i % 3 == 0 ? x : (i % 3 == 1 ? y : z)).add(m, box, c);
    all.add(m, box, c);
  }
  Bins xyz = x, zyx = z;
  xyz.merge(y);
  xyz.merge(z);
  zyx.merge(y);
  zyx.merge(x);
  for (size_t i = 0; i < all.boxes.size(); ++i) {
    EXPECT_EQ(xyz.box(i), all.box(i));
    EXPECT_EQ(zyx.box(i), all.box(i));
  }
  EXPECT_EQ(xyz.counts, all.counts);
  EXPECT_EQ(zyx.counts, all.counts);
}

// The small-node shortcut must give the bins' answer bit for bit.
TEST(Binning, SmallNodeShortcutEqualsBins) {
  uint64_t seed = 7;
  auto rnd = [&] {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    return float(seed >> 40) / float(1 << 24);
  };
  for (int trial = 0; trial < 300; ++trial) {
    const size_t n = 2 + trial % (kSmallNodeMax - 1);
    const int bin_count = trial % 3 == 0 ? 4 : 32;
    std::vector<AABB> boxes;
    std::vector<Vec3f> cents;
    std::vector<BoxRef> refs;
    AABB parent, cb;
    for (size_t i = 0; i < n; ++i) {
      // Coarse positions make shared bins and equal costs (ties) likely.
      const Vec3f lo{float(int(rnd() * 4)), float(int(rnd() * 3)), rnd()};
      const AABB b(lo, lo + Vec3f{0.5f + rnd(), 0.5f, 0.25f + float(i % 2)});
      boxes.push_back(b);
      cents.push_back(b.center());
      refs.push_back(make_box_ref(b, static_cast<uint32_t>(i)));
      parent.extend(b);
      cb.extend(b.center());
    }
    const BinMapping m(cb, bin_count);
    Bins bins(bin_count);
    for (size_t i = 0; i < n; ++i) bins.add(m, boxes[i], cents[i]);
    std::vector<float> sa;
    std::vector<uint32_t> sc;
    const BinnedSplit a = find_binned_split(bins, m, SahParams{}, parent.half_area(), sa, sc);
    const BinnedSplit b =
        find_binned_split_small(refs.data(), n, m, SahParams{}, parent.half_area());
    ASSERT_EQ(a.axis, b.axis) << trial;
    EXPECT_EQ(a.cut, b.cut) << trial;
    EXPECT_EQ(a.cost, b.cost) << trial;
    EXPECT_EQ(a.left_count, b.left_count) << trial;
    EXPECT_EQ(a.right_count, b.right_count) << trial;
    EXPECT_EQ(a.left_bounds, b.left_bounds) << trial;
    EXPECT_EQ(a.right_bounds, b.right_bounds) << trial;
  }
}

// The 16-cut sweep (binned_sweep16.h) must price and pick exactly as the
// scalar sweep: every bin count around the vector width, empty bins, ties,
// flat axes, blocks of leaf_block triangles.
TEST(Binning, SixteenCutSweepEqualsScalarSweep) {
#ifndef HPRT_HAS_BINNED_SWEEP16
  GTEST_SKIP() << "built without AVX-512: only the scalar sweep exists";
#else
  uint64_t seed = 11;
  auto rnd = [&] {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    return float(seed >> 40) / float(1 << 24);
  };
  const int kBinCounts[] = {2, 3, 5, 15, 16, 17, 31, 32, 33, 48, 64, 100, 1024};
  const auto scalar = [](auto&&... args) { detail::sweep_axis_scalar(args...); };
  int splits = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int bin_count = kBinCounts[trial % std::size(kBinCounts)];
    const size_t n = 2 + size_t(rnd() * (trial % 5 == 0 ? 3000.0f : 200.0f));
    const bool coarse = trial % 2 == 0, flat_y = trial % 7 == 0;
    SahParams sah;
    sah.leaf_block = trial % 4 == 0 ? 4 : 1;
    sah.traversal_cost = trial % 3 == 0 ? 1.0f : 2.0f;
    Bins bins(bin_count);
    std::vector<AABB> boxes;
    AABB parent, cb;
    for (size_t i = 0; i < n; ++i) {
      // Coarse positions leave bins empty and make equal costs (ties) likely.
      const Vec3f lo =
          coarse ? Vec3f{float(int(rnd() * 5)), float(int(rnd() * 3)), float(int(rnd() * 9))}
                 : Vec3f{rnd() * 10.0f, rnd(), rnd() * 3.0f};
      const AABB b(flat_y ? Vec3f{lo.x, 1.0f, lo.z} : lo,
                   (flat_y ? Vec3f{lo.x, 1.0f, lo.z} : lo) +
                       Vec3f{0.5f * rnd(), flat_y ? 0.0f : 0.5f, 0.25f + float(i % 2)});
      boxes.push_back(b);
      parent.extend(b);
      cb.extend(b.center());
    }
    const BinMapping m(cb, bin_count);
    for (const AABB& b : boxes) bins.add(m, b, b.center());
    std::vector<float> sa, va;
    std::vector<uint32_t> sc, vc;
    const BinnedSplit a =
        detail::find_binned_split_with(scalar, bins, m, sah, parent.half_area(), sa, sc);
    const BinnedSplit b = find_binned_split(bins, m, sah, parent.half_area(), va, vc);
    ASSERT_EQ(a.axis, b.axis) << trial;
    EXPECT_EQ(a.cut, b.cut) << trial;
    EXPECT_EQ(std::bit_cast<uint32_t>(a.cost), std::bit_cast<uint32_t>(b.cost)) << trial;
    EXPECT_EQ(a.left_count, b.left_count) << trial;
    EXPECT_EQ(a.right_count, b.right_count) << trial;
    EXPECT_EQ(a.left_bounds, b.left_bounds) << trial;
    EXPECT_EQ(a.right_bounds, b.right_bounds) << trial;
    splits += a.axis >= 0;
  }
  EXPECT_GT(splits, 1500);  // the trials are not all without a cut
#endif
}

}  // namespace
}  // namespace hprt
