// Tests of build_parallel: canonical layout and invariants, options, fallbacks.
#include <gtest/gtest.h>

#include "core/parallel.h"
#include "tests/support/bvh_builder_checks.h"

namespace hprt::test {
namespace {

TEST(BuilderParallel, InvariantsHoldOnAllMeshes) { check_invariants_on_meshes(build_parallel); }
TEST(BuilderParallel, LeafSizeOptionIsRespected) { check_leaf_sizes(build_parallel); }
TEST(BuilderParallel, InvalidTrianglesAreLeftOutAndCounted) {
  check_invalid_triangles(build_parallel);
}
TEST(BuilderParallel, CoincidentCentroidsFallBackToMedian) {
  check_coincident_centroids(build_parallel);
}
TEST(BuilderParallel, DepthStaysWithinLimit) { check_depth_limit(build_parallel); }
TEST(BuilderParallel, EmptyAndSingleInput) { check_empty_and_single(build_parallel); }
TEST(BuilderParallel, BadOptionsThrow) { check_bad_options(build_parallel); }

BuildTree parallel_with_threads(const PrimInfo& p, const BuildOptions& o, int threads) {
  return run_with_threads(threads, [&] { return build_parallel(p, o); });
}

// The tree never depends on the thread count and equals the sequential binned tree.
TEST(BuilderParallel, EqualsBinnedForAnyThreadCount) {
  const PrimInfo p = prims_of(random_soup(200000, 21));
  const BuildTree ref = build_binned(p, BuildOptions{});
  ASSERT_EQ(check_tree(ref, p, 4), "");
  for (int threads : {1, 2, 7, 16}) {
    const BuildTree t = parallel_with_threads(p, BuildOptions{}, threads);
    EXPECT_TRUE(t == ref) << threads << " threads";
  }
}

TEST(BuilderParallel, SmallCutoffStitchesSubtreesExactly) {
  const PrimInfo p = prims_of(random_soup(20000, 22));
  for (int cutoff : {1, 2, 64}) {
    BuildOptions o;
    o.parallel_cutoff = cutoff;
    const BuildTree ref = build_binned(p, o);
    for (int threads : {1, 2, 7, 16})
      EXPECT_TRUE(parallel_with_threads(p, o, threads) == ref)
          << "cutoff " << cutoff << ", " << threads << " threads";
  }
}

TEST(BuilderParallel, EqualsBinnedForEveryBinCount) {
  const PrimInfo p = prims_of(grid(120, 100));
  for (int bins : {4, 16, 32, 64}) {
    BuildOptions o;
    o.bins = bins;
    o.parallel_cutoff = 256;
    const BuildTree ref = build_binned(p, o);
    for (int threads : {1, 2, 7, 16})
      EXPECT_TRUE(parallel_with_threads(p, o, threads) == ref)
          << bins << " bins, " << threads << " threads";
  }
}

TEST(BuilderParallel, FallbacksAtTheParallelTopMatchBinned) {
  // Coincident centroids and the depth guard take the median path above the cut-off.
  for (const TriangleMesh& m : {coincident_centroids(3000), exponential_spacing(200)}) {
    const PrimInfo p = prims_of(m);
    BuildOptions o;
    o.parallel_cutoff = 16;
    o.max_leaf_size = 1;
    const BuildTree ref = build_binned(p, o);
    for (int threads : {1, 2, 7, 16})
      EXPECT_TRUE(parallel_with_threads(p, o, threads) == ref) << m.name << " " << threads;
  }
}

}  // namespace
}  // namespace hprt::test
