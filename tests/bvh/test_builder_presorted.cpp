// Tests of build_presorted: canonical layout and invariants, options, fallbacks.
#include <gtest/gtest.h>

#include "tests/support/bvh_builder_checks.h"

namespace hprt::test {
namespace {

TEST(BuilderPresorted, InvariantsHoldOnAllMeshes) { check_invariants_on_meshes(build_presorted); }
TEST(BuilderPresorted, LeafSizeOptionIsRespected) { check_leaf_sizes(build_presorted); }
TEST(BuilderPresorted, InvalidTrianglesAreLeftOutAndCounted) {
  check_invalid_triangles(build_presorted);
}
TEST(BuilderPresorted, CoincidentCentroidsFallBackToMedian) {
  check_coincident_centroids(build_presorted);
}
TEST(BuilderPresorted, DepthStaysWithinLimit) { check_depth_limit(build_presorted); }
TEST(BuilderPresorted, EmptyAndSingleInput) { check_empty_and_single(build_presorted); }
TEST(BuilderPresorted, BadOptionsThrow) { check_bad_options(build_presorted); }

// Algorithm 2 must give exactly Algorithm 1's tree.
TEST(BuilderPresorted, EqualsSweepExactly) {
  const TriangleMesh meshes[] = {random_soup(2000, 5),
                                 grid(25, 25),
                                 icosphere(3),
                                 coincident_centroids(40),
                                 duplicates(150, 3, 6),
                                 exponential_spacing(120),
                                 with_invalid_triangles(),
                                 random_soup(500, 7, 0.5f)};
  for (const TriangleMesh& m : meshes) {
    const PrimInfo p = prims_of(m);
    for (int leaf : {1, 4, 8}) {
      BuildOptions o;
      o.max_leaf_size = leaf;
      const BuildTree a = build_sweep(p, o);
      const BuildTree b = build_presorted(p, o);
      EXPECT_TRUE(a == b) << m.name << " leaf " << leaf;
      EXPECT_EQ(compute_tree_stats(a, p).tree_hash, compute_tree_stats(b, p).tree_hash);
    }
  }
}

}  // namespace
}  // namespace hprt::test
