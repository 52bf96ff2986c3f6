// Tests of build_binned: canonical layout and invariants, options, fallbacks.
#include <gtest/gtest.h>

#include "tests/support/bvh_builder_checks.h"

namespace hprt::test {
namespace {

TEST(BuilderBinned, InvariantsHoldOnAllMeshes) { check_invariants_on_meshes(build_binned); }
TEST(BuilderBinned, LeafSizeOptionIsRespected) { check_leaf_sizes(build_binned); }
TEST(BuilderBinned, InvalidTrianglesAreLeftOutAndCounted) { check_invalid_triangles(build_binned); }
TEST(BuilderBinned, CoincidentCentroidsFallBackToMedian) {
  check_coincident_centroids(build_binned);
}
TEST(BuilderBinned, DepthStaysWithinLimit) { check_depth_limit(build_binned); }
TEST(BuilderBinned, EmptyAndSingleInput) { check_empty_and_single(build_binned); }
TEST(BuilderBinned, BadOptionsThrow) { check_bad_options(build_binned); }

// Binning loses little: SAH cost within 5% of the full sweep on 10k-50k meshes.
TEST(BuilderBinned, SahCostWithinFivePercentOfSweep) {
  const TriangleMesh meshes[] = {random_soup(20000, 11), grid(100, 100), icosphere(5)};
  for (const TriangleMesh& m : meshes) {
    const PrimInfo p = prims_of(m);
    const double sweep = compute_tree_stats(build_sweep(p, BuildOptions{}), p).sah_cost;
    const double binned = compute_tree_stats(build_binned(p, BuildOptions{}), p).sah_cost;
    EXPECT_LE(binned, sweep * 1.05) << m.name << " sweep " << sweep << " binned " << binned;
    EXPECT_GT(binned, 0.0);
  }
}

TEST(BuilderBinned, BinCountsGiveValidTrees) {
  const PrimInfo p = prims_of(random_soup(5000, 12));
  double cost4 = 0, cost64 = 0;
  for (int bins : {2, 4, 16, 32, 64, 256}) {
    BuildOptions o;
    o.bins = bins;
    const BuildTree t = build_binned(p, o);
    EXPECT_EQ(check_tree(t, p, 4), "") << bins << " bins";
    if (bins == 4) cost4 = compute_tree_stats(t, p).sah_cost;
    if (bins == 64) cost64 = compute_tree_stats(t, p).sah_cost;
  }
  EXPECT_LT(cost64, cost4);  // more bins, better splits
}

TEST(BuilderBinned, LeavesListPrimitivesInAscendingOrder) {
  const PrimInfo p = prims_of(random_soup(3000, 13));
  const BuildTree t = build_binned(p, BuildOptions{});
  for (const BuildNode& n : t.nodes)
    if (n.is_leaf()) {
      for (uint32_t k = n.first + 1; k < n.first + n.count; ++k)
        EXPECT_LT(t.prim_order[k - 1], t.prim_order[k]);
    }
}

}  // namespace
}  // namespace hprt::test
