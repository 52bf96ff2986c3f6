// Tests of compute_tree_stats: counts, depth, normalised SAH cost, tree hash.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <utility>
#include <vector>

#include "bvh/builders/builders.h"
#include "core/parallel.h"
#include "tests/support/bvh_test_meshes.h"

namespace hprt::test {
namespace {

// Root [0,2]x[0,1]x[0,1] (half area 5) over leaves [0,1]^3 (3 prims, half
// area 3) and an inner node [1,2]x[0,1]x[0,1] (3) over two unit leaves (1 prim each).
struct HandTree {
  PrimInfo prims;
  BuildTree tree;
  HandTree() {
    prims.bounds = BuildArray<AABB>(5);
    prims.centroids = BuildArray<Vec3f>(5);
    prims.refs = BuildArray<PrimRef>(5);
    for (uint32_t i = 0; i < 5; ++i) {
      prims.bounds[i] = AABB({0, 0, 0}, {1, 1, 1});
      prims.centroids[i] = {0.5f, 0.5f, 0.5f};
      prims.refs[i] = {0, i};
    }
    const AABB unit({0, 0, 0}, {1, 1, 1}), right({1, 0, 0}, {2, 1, 1}), root({0, 0, 0}, {2, 1, 1});
    tree.nodes = {
        {root, 2, 0, 0}, {unit, 0, 0, 3}, {right, 4, 0, 0}, {right, 0, 3, 1}, {right, 0, 4, 1}};
    tree.prim_order = {0, 1, 2, 3, 4};
  }
};

TEST(TreeStats, CountsDepthAndNormalisedSah) {
  HandTree h;
  const TreeStats s = compute_tree_stats(h.tree, h.prims);
  EXPECT_EQ(s.triangles, 5u);
  EXPECT_EQ(s.nodes, 5u);
  EXPECT_EQ(s.leaves, 3u);
  EXPECT_EQ(s.depth, 3);  // root is depth 1
  EXPECT_EQ(s.max_leaf_size, 3);
  EXPECT_DOUBLE_EQ(s.avg_leaf_size, 5.0 / 3.0);
  // inner: 5/5 + 3/5; leaves: 3/5 * 3 + 3/5 * 1 + 3/5 * 1
  EXPECT_NEAR(s.sah_cost, 1.0 + 0.6 + 1.8 + 0.6 + 0.6, 1e-12);
}

TEST(TreeStats, HashSeesEveryBoundBitAndThePrimitiveOrder) {
  HandTree h;
  const uint64_t base = compute_tree_stats(h.tree, h.prims).tree_hash;
  EXPECT_EQ(compute_tree_stats(HandTree().tree, h.prims).tree_hash, base);  // equal trees
  for (size_t node = 0; node < h.tree.nodes.size(); ++node) {
    HandTree p;
    p.tree.nodes[node].bounds.max.z = std::nextafter(p.tree.nodes[node].bounds.max.z, 9.0f);
    EXPECT_NE(compute_tree_stats(p.tree, p.prims).tree_hash, base) << node;
  }
  HandTree swapped;
  std::swap(swapped.tree.prim_order[0], swapped.tree.prim_order[4]);
  EXPECT_NE(compute_tree_stats(swapped.tree, swapped.prims).tree_hash, base);
  HandTree relinked;
  relinked.tree.nodes[3].first = 4;
  relinked.tree.nodes[4].first = 3;
  EXPECT_NE(compute_tree_stats(relinked.tree, relinked.prims).tree_hash, base);
  // The hash reads (geomID, primID), so the same order over other refs differs.
  HandTree other_refs;
  other_refs.prims.refs[2].geom_id = 1;
  EXPECT_NE(compute_tree_stats(other_refs.tree, other_refs.prims).tree_hash, base);
}

TEST(TreeStats, BuiltTreesHashEquallyAndDifferAcrossBuilders) {
  const PrimInfo p = prims_of(random_soup(3000, 31));
  const TreeStats a = compute_tree_stats(build_binned(p, BuildOptions{}), p);
  const TreeStats b = compute_tree_stats(build_binned(p, BuildOptions{}), p);
  const TreeStats c = compute_tree_stats(build_sweep(p, BuildOptions{}), p);
  EXPECT_EQ(a.tree_hash, b.tree_hash);
  EXPECT_NE(a.tree_hash, c.tree_hash);
  EXPECT_EQ(a.triangles, 3000u);
  EXPECT_EQ(a.nodes, 2 * a.leaves - 1);
  EXPECT_GT(a.sah_cost, 1.0);
  EXPECT_GE(a.depth, 12);  // at least log2(3000 / 4)
}

// Computed in parallel over fixed chunks: every figure, the SAH sum's bits
// included, is the same for any thread count (trees of many chunks).
TEST(TreeStats, SameFiguresForAnyThreadCount) {
  const PrimInfo p = prims_of(random_soup(60000, 33));
  const BuildTree t = build_binned(p, BuildOptions{});
  const TreeStats one = run_with_threads(1, [&] { return compute_tree_stats(t, p); });
  for (int threads : {2, 7}) {
    const TreeStats s = run_with_threads(threads, [&] { return compute_tree_stats(t, p); });
    EXPECT_EQ(s.tree_hash, one.tree_hash) << threads;
    EXPECT_EQ(std::bit_cast<uint64_t>(s.sah_cost), std::bit_cast<uint64_t>(one.sah_cost));
    EXPECT_EQ(s.depth, one.depth);
    EXPECT_EQ(s.leaves, one.leaves);
    EXPECT_EQ(s.max_leaf_size, one.max_leaf_size);
  }
  // Depth by an explicit walk.
  int deepest = 0;
  std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
  while (!stack.empty()) {
    const auto [i, d] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, d);
    if (!t.nodes[i].is_leaf()) {
      stack.push_back({i + 1, d + 1});
      stack.push_back({t.nodes[i].right, d + 1});
    }
  }
  EXPECT_EQ(one.depth, deepest);
}

// build_tree_sah_cost: compute_tree_stats' sah_cost, bit for bit, whatever
// the builder and the thread count (the backend takes it as the rebuilt
// tree's cost); trees of many chunks, a hand tree, a single leaf, no tree.
TEST(TreeStats, SahCostAloneIsTheStatsSahCost) {
  const PrimInfo p = prims_of(random_soup(60000, 34));
  for (const BuildTree& t : {build_binned(p, BuildOptions{}), build_morton(p, BuildOptions{})}) {
    const uint64_t stats = std::bit_cast<uint64_t>(compute_tree_stats(t, p).sah_cost);
    for (int threads : {1, 2, 7})
      EXPECT_EQ(std::bit_cast<uint64_t>(
                    run_with_threads(threads, [&] { return build_tree_sah_cost(t); })),
                stats)
          << threads;
  }
  HandTree h;
  EXPECT_NEAR(build_tree_sah_cost(h.tree), 1.0 + 0.6 + 1.8 + 0.6 + 0.6, 1e-12);
  BuildOptions o;
  o.sah.traversal_cost = 100.0f;  // makes the root a leaf
  const PrimInfo three = prims_of(random_soup(3, 32, 0.5f));
  EXPECT_EQ(build_tree_sah_cost(build_binned(three, o)), 3.0);
  EXPECT_EQ(build_tree_sah_cost(BuildTree{}), 0.0);
}

TEST(TreeStats, SingleLeafCostsItsTriangleCount) {
  const PrimInfo p = prims_of(random_soup(3, 32, 0.5f));
  BuildOptions o;
  o.sah.traversal_cost = 100.0f;  // makes the root a leaf
  const TreeStats s = compute_tree_stats(build_binned(p, o), p);
  EXPECT_EQ(s.nodes, 1u);
  EXPECT_EQ(s.depth, 1);
  EXPECT_DOUBLE_EQ(s.sah_cost, 3.0);
}

}  // namespace
}  // namespace hprt::test
