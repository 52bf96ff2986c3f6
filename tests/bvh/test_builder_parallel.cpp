// Tests of build_parallel: canonical layout and invariants, options, fallbacks.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <stdexcept>

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

// build_tree_releasing_bounds: the same tree for every builder, the boxes
// gone afterwards (but for Morton's) and PrimInfo::box giving their bits.
TEST(BuildTreeReleasingBounds, SameTreeEveryBuilderBoxesFromTheScene) {
  Scene scene;
  scene.add_mesh(random_soup(5000, 31));
  scene.add_mesh(with_invalid_triangles());
  for (const BuilderKind builder :
       {BuilderKind::kSweep, BuilderKind::kPresorted, BuilderKind::kBinned, BuilderKind::kParallel,
        BuilderKind::kMorton}) {
    SCOPED_TRACE(to_string(builder));
    BuildOptions o;
    o.builder = builder;
    const PrimInfo p = make_prim_info(scene);
    const BuildTree ref = build_tree(p, o);
    PrimInfo released = p;
    EXPECT_TRUE(build_tree_releasing_bounds(released, o) == ref);
    // Kept for a Morton tree (its layout reads many of them).
    EXPECT_EQ(released.bounds.empty(), builder != BuilderKind::kMorton);
    if (builder == BuilderKind::kMorton) continue;
    // A released prim info builds no tree.
    EXPECT_THROW(build_tree(released, o), std::invalid_argument);
    for (size_t i = 0; i < p.size(); ++i) {
      const AABB a = released.box(i, scene), b = p.bounds[i];
      ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "box " << i;
    }
  }
}

// The binned builders never read the boxes after `refs_filled`: boxes
// overwritten there with NaN leave the tree as it was.
TEST(BuildTreeReleasingBounds, BinnedBuildersReadNoBoxAfterTheCallback) {
  const PrimInfo p = prims_of(random_soup(30000, 32));
  BuildOptions o;
  o.parallel_cutoff = 64;  // many parallel levels
  const BuildTree ref = build_binned(p, o);
  for (const bool parallel : {false, true}) {
    PrimInfo q = p;
    int calls = 0;
    const auto poison = [&] {
      ++calls;
      const float nan = std::numeric_limits<float>::quiet_NaN();
      for (size_t i = 0; i < q.size(); ++i) q.bounds[i] = AABB({nan, nan, nan}, {nan, nan, nan});
    };
    const BuildTree t = parallel ? run_with_threads(2, [&] { return build_parallel(q, o, poison); })
                                 : build_binned(q, o, poison);
    EXPECT_EQ(calls, 1) << parallel;
    EXPECT_TRUE(t == ref) << parallel;
  }
}

}  // namespace
}  // namespace hprt::test
