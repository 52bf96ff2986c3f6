// Tests of build_morton: canonical layout and invariants, options, the
// median fallback, Morton order, thread independence, and quality (SAH cost)
// against the binned SAH builder.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/parallel.h"
#include "tests/support/bvh_builder_checks.h"

namespace hprt::test {
namespace {

TEST(BuilderMorton, InvariantsHoldOnAllMeshes) { check_invariants_on_meshes(build_morton); }
// Splits until a range fits in a leaf, whatever the SAH constants.
TEST(BuilderMorton, LeafSizeOptionIsRespected) {
  check_leaf_sizes(build_morton, false);
  const PrimInfo p = prims_of(random_soup(2000, 3));
  BuildOptions o;
  o.max_leaf_size = 8;
  const BuildTree t = build_morton(p, o);
  o.sah.traversal_cost = 1000.0f;
  EXPECT_TRUE(build_morton(p, o) == t);
}
TEST(BuilderMorton, InvalidTrianglesAreLeftOutAndCounted) { check_invalid_triangles(build_morton); }
// All codes equal: every split is the object median of the other builders.
TEST(BuilderMorton, CoincidentCentroidsFallBackToMedian) {
  check_coincident_centroids(build_morton);
}
TEST(BuilderMorton, EmptyAndSingleInput) { check_empty_and_single(build_morton); }
TEST(BuilderMorton, BadOptionsThrow) { check_bad_options(build_morton); }

// Exponentially spaced centroids fall into a few grid cells: the ties split
// at the middle, and the tree stays valid and within the depth limit.
TEST(BuilderMorton, DepthStaysWithinLimit) {
  for (size_t n : {240u, 5000u}) {
    const PrimInfo p = prims_of(exponential_spacing(n));
    BuildOptions o;
    o.max_leaf_size = 1;
    const BuildTree t = build_morton(p, o);
    EXPECT_EQ(check_tree(t, p, 1), "");
    EXPECT_LE(compute_tree_stats(t, p).depth, kMaxBuildDepth);
  }
}

// The grid cell of a centroid along each axis, as build_morton quantises.
uint32_t cell(float v, float lo, float hi) {
  if (!(hi > lo)) return 0;
  const double f = (double(v) - lo) * 1024.0 / (double(hi) - double(lo));
  return f > 0.0 ? uint32_t(std::min(f, 1023.0)) : 0u;
}
uint32_t morton_code(const PrimInfo& p, uint32_t i) {
  const Vec3f& c = p.centroids[i];
  const AABB& b = p.centroid_bounds;
  const uint32_t q[3] = {cell(c.x, b.min.x, b.max.x), cell(c.y, b.min.y, b.max.y),
                         cell(c.z, b.min.z, b.max.z)};
  uint32_t code = 0;
  for (int bit = 9; bit >= 0; --bit)
    for (int axis = 0; axis < 3; ++axis) code = code << 1 | ((q[axis] >> bit) & 1u);
  return code;
}

// prim_order is sorted by Morton code (bit-by-bit interleaving here, not the
// builder's bit tricks), equal codes by index; and every inner node's left
// child holds codes whose split bit is 0 and the right child 1, unless all
// codes of the node are equal.
TEST(BuilderMorton, LeavesFollowMortonOrderAndSplitsFollowCodeBits) {
  const PrimInfo p = prims_of(random_soup(30000, 31));
  const BuildTree t = build_morton(p, BuildOptions{});
  ASSERT_EQ(check_tree(t, p, 4), "");
  for (size_t k = 1; k < t.prim_order.size(); ++k) {
    const uint32_t a = t.prim_order[k - 1], b = t.prim_order[k];
    const uint32_t ca = morton_code(p, a), cb = morton_code(p, b);
    ASSERT_TRUE(ca < cb || (ca == cb && a < b)) << k;
  }
  // Ranges of the nodes: a leaf's own, an inner node's from its children.
  std::vector<std::pair<uint32_t, uint32_t>> range(t.nodes.size());
  for (size_t i = t.nodes.size(); i-- > 0;) {
    const BuildNode& n = t.nodes[i];
    range[i] = n.is_leaf() ? std::pair{n.first, n.first + n.count}
                           : std::pair{range[i + 1].first, range[n.right].second};
  }
  size_t bit_splits = 0;
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const BuildNode& n = t.nodes[i];
    if (n.is_leaf()) continue;
    const uint32_t first = morton_code(p, t.prim_order[range[i].first]);
    const uint32_t last = morton_code(p, t.prim_order[range[i].second - 1]);
    const uint32_t mid = range[n.right].first;
    if (first == last) {
      EXPECT_EQ(mid - range[i].first, (range[i].second - range[i].first) / 2);
      continue;
    }
    const uint32_t bit = 1u << (31 - std::countl_zero(first ^ last));
    EXPECT_EQ(morton_code(p, t.prim_order[mid - 1]) & bit, 0u);
    EXPECT_NE(morton_code(p, t.prim_order[mid]) & bit, 0u);
    ++bit_splits;
  }
  EXPECT_GT(bit_splits, t.nodes.size() / 4);
}

// The tree depends neither on the thread count nor on the parallel cut-off.
TEST(BuilderMorton, SameTreeForAnyThreadCountAndCutoff) {
  const PrimInfo p = prims_of(random_soup(100000, 32));
  BuildOptions sequential;
  sequential.parallel_cutoff = 1 << 30;
  const BuildTree ref = build_morton(p, sequential);
  ASSERT_EQ(check_tree(ref, p, 4), "");
  for (int cutoff : {1, 64, 4096})
    for (int threads : {1, 2, 7}) {
      BuildOptions o;
      o.parallel_cutoff = cutoff;
      const BuildTree t = run_with_threads(threads, [&] { return build_morton(p, o); });
      EXPECT_TRUE(t == ref) << "cutoff " << cutoff << ", " << threads << " threads";
    }
}

// No SAH, so dearer trees than binned SAH, but within a bound (measured: see
// the ratios printed).
TEST(BuilderMorton, SahCostWithinBoundOfBinned) {
  const TriangleMesh meshes[] = {random_soup(20000, 11), grid(100, 100), icosphere(5)};
  for (const TriangleMesh& m : meshes) {
    const PrimInfo p = prims_of(m);
    const double binned = compute_tree_stats(build_binned(p, BuildOptions{}), p).sah_cost;
    const double morton = compute_tree_stats(build_morton(p, BuildOptions{}), p).sah_cost;
    std::printf("%s: SAH morton %.2f, binned %.2f (%.3fx)\n", m.name.c_str(), morton, binned,
                morton / binned);
    EXPECT_GE(morton, binned * 0.99) << m.name;
    EXPECT_LE(morton, binned * 1.6) << m.name;
  }
}

}  // namespace
}  // namespace hprt::test
