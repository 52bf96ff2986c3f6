// Flattening: node boxes contain their children, sibling pairs are adjacent
// and 64-byte aligned, every valid input triangle appears exactly once in
// leaf order with its input (geomID, primID) and its precomputed data.
#include "bvh/layout/flatten_bvh2.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "bvh/refit/refit_bvh2.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

AABB box_of(const BinaryNode& n) { return AABB{n.min, n.max}; }

// Walks the flat tree; returns the number of nodes reached, checks boxes.
size_t walk(const Bvh2& f, uint32_t i, std::vector<int>& tri_seen, int depth, int& max_depth) {
  const BinaryNode& n = f.nodes.at(i);
  max_depth = std::max(max_depth, depth);
  if (n.is_leaf()) {
    for (uint32_t k = n.index; k < n.index + n.count; ++k) {
      ++tri_seen.at(k);
      AABB t;
      const TriangleVerts v = f.triangles.triangle(LeafRange::whole(n.index, n.count), k);
      t.extend(v.v0);
      t.extend(v.v1);
      t.extend(v.v2);
      EXPECT_TRUE(box_of(n).contains(t)) << "leaf " << i << " tri " << k;
    }
    return 1;
  }
  EXPECT_EQ(n.index % 2, 0u) << "pair not at an even slot";
  EXPECT_TRUE(box_of(n).contains(box_of(f.nodes.at(n.index))));
  EXPECT_TRUE(box_of(n).contains(box_of(f.nodes.at(n.index + 1))));
  return 1 + walk(f, n.index, tri_seen, depth + 1, max_depth) +
         walk(f, n.index + 1, tri_seen, depth + 1, max_depth);
}

void check(const test::BuiltBvh& b) {
  const Bvh2& f = b.bvh;
  ASSERT_FALSE(f.empty());
  EXPECT_EQ(reinterpret_cast<uintptr_t>(f.nodes.data()) % 64, 0u);
  EXPECT_EQ(f.nodes.size(), b.tree.nodes.size() == 1 ? 1 : b.tree.nodes.size() + 1);
  std::vector<int> seen(f.triangles.size(), 0);
  int depth = 0;
  EXPECT_EQ(walk(f, 0, seen, 1, depth), b.tree.nodes.size());
  EXPECT_LE(depth, kMaxBuildDepth);
  for (int s : seen) ASSERT_EQ(s, 1);
  // Each valid input triangle exactly once, with its own vertices and edges.
  std::vector<std::vector<int>> per_input(b.scene.meshes.size());
  for (size_t g = 0; g < b.scene.meshes.size(); ++g)
    per_input[g].assign(b.scene.meshes[g].triangle_count(), 0);
  const std::vector<LeafRange> leaves = test::leaf_of_each(f);
  for (uint32_t k = 0; k < f.triangles.size(); ++k) {
    const PrimRef r = f.triangles.refs[k];
    EXPECT_EQ(r, b.prims.refs[b.tree.prim_order[k]]);
    const TriangleMesh& m = b.scene.meshes.at(r.geom_id);
    ++per_input[r.geom_id].at(r.prim_id);
    const Vec3u t = m.triangles[r.prim_id];
    const TriangleVerts v = f.triangles.triangle(leaves[k], k);
    EXPECT_EQ(v.v0, m.positions[t[0]]);
    EXPECT_EQ(v.v1, m.positions[t[1]]);
    EXPECT_EQ(v.v2, m.positions[t[2]]);
    EXPECT_EQ(f.triangles.edges[k].v0, m.positions[t[0]]);
    EXPECT_EQ(f.triangles.edges[k].e1, m.positions[t[1]] - m.positions[t[0]]);
    EXPECT_EQ(f.triangles.edges[k].e2, m.positions[t[2]] - m.positions[t[0]]);
  }
  for (size_t g = 0; g < per_input.size(); ++g)
    for (size_t i = 0; i < per_input[g].size(); ++i)
      EXPECT_EQ(per_input[g][i], b.scene.meshes[g].triangle_valid(i) ? 1 : 0) << g << "/" << i;
  EXPECT_EQ(f.memory_bytes(),
            f.nodes.size() * 32 + f.triangles.size() * (6 * sizeof(Vec3f) + sizeof(PrimRef)));
}

TEST(Flatten, SoupTwoMeshesAllLeafSizes) {
  for (int leaf : {1, 2, 4, 8}) {
    BuildOptions o;
    o.max_leaf_size = leaf;
    check(test::build_flat({test::random_soup(2000, 1), test::grid(10, 10)}, o));
  }
}

TEST(Flatten, InvalidTrianglesLeftOutAndSingleLeaf) {
  check(test::build_flat({test::with_invalid_triangles()}, BuildOptions{}));
  TriangleMesh one;
  test::add_triangle(one, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const test::BuiltBvh b = test::build_flat({one}, BuildOptions{});
  ASSERT_EQ(b.bvh.nodes.size(), 1u);
  EXPECT_TRUE(b.bvh.nodes[0].is_leaf());
  check(b);
}

// Keeping one test's array: that array is the same as with both, the other
// is not held, and memory counts only what is held. A refit of an array
// that is not held is refused.
TEST(Flatten, KeepsOnlyTheTriangleArraysAskedFor) {
  const test::BuiltBvh b = test::build_flat({test::random_soup(2000, 3)}, BuildOptions{});
  const size_t n = b.bvh.triangles.size();
  const Bvh2 verts = flatten(b.tree, b.prims, b.scene, TriangleArrays::kVerts);
  const Bvh2 edges = flatten(b.tree, b.prims, b.scene, TriangleArrays::kEdges);
  EXPECT_TRUE(b.bvh.triangles.holds(TriangleArrays::kBoth));
  EXPECT_TRUE(verts.triangles.holds(TriangleArrays::kVerts));
  EXPECT_FALSE(verts.triangles.holds(TriangleArrays::kEdges));
  EXPECT_TRUE(edges.triangles.holds(TriangleArrays::kEdges));
  EXPECT_FALSE(edges.triangles.holds(TriangleArrays::kBoth));
  EXPECT_TRUE(verts.triangles.edges.empty());
  EXPECT_TRUE(edges.triangles.verts.empty());
  ASSERT_EQ(verts.triangles.verts.size(), 9 * n);
  EXPECT_EQ(std::memcmp(verts.triangles.verts.data(), b.bvh.triangles.verts.data(),
                        9 * n * sizeof(float)),
            0);
  for (size_t k = 0; k < n; ++k) {
    EXPECT_EQ(verts.triangles.refs[k], b.bvh.triangles.refs[k]);
    EXPECT_EQ(
        std::memcmp(&edges.triangles.edges[k], &b.bvh.triangles.edges[k], sizeof(TriangleEdges)),
        0);
  }
  EXPECT_EQ(verts.memory_bytes(), b.bvh.memory_bytes() - n * sizeof(TriangleEdges));
  EXPECT_EQ(edges.memory_bytes(), b.bvh.memory_bytes() - n * sizeof(TriangleVerts));
  Bvh2 v = verts;
  EXPECT_THROW(refit(v, b.scene, RefitTriangles::kEdges, nullptr), std::invalid_argument);
  EXPECT_THROW(refit(v, b.scene, RefitTriangles::kBoth, nullptr), std::invalid_argument);
  EXPECT_TRUE(refit(v, b.scene, RefitTriangles::kVerts, nullptr).valid);
}

// A rebuild gathers into the last build's arrays: the same size keeps the
// storage (every triangle rewritten), another size or array set reallocates;
// the result equals a fresh gather either way. The node pass alone gives the
// nodes of flatten.
TEST(Flatten, GatherIntoReusedStorageEqualsAFreshGather) {
  const test::BuiltBvh b = test::build_flat({test::random_soup(3000, 5)}, BuildOptions{});
  const Bvh2 nodes = flatten_nodes(b.tree, b.prims);
  ASSERT_EQ(nodes.nodes.size(), b.bvh.nodes.size());
  EXPECT_EQ(
      std::memcmp(nodes.nodes.data(), b.bvh.nodes.data(), nodes.nodes.size() * sizeof(BinaryNode)),
      0);
  EXPECT_EQ(nodes.triangles.size(), 0u);
  const LeafTriangles fresh =
      gather_leaf_triangles(b.tree, b.prims, b.scene, TriangleArrays::kVerts);
  LeafTriangles reused;
  reused.allocate(fresh.size(), TriangleArrays::kVerts);
  for (float& x : reused.verts) x = 0.0f;  // stale contents
  const float* storage = reused.verts.data();
  gather_leaf_triangles(b.tree, b.prims, b.scene, TriangleArrays::kVerts, reused);
  EXPECT_EQ(reused.verts.data(), storage);
  EXPECT_EQ(
      std::memcmp(reused.verts.data(), fresh.verts.data(), fresh.verts.size() * sizeof(float)), 0);
  EXPECT_EQ(reused.refs, fresh.refs);
  // Other arrays asked for: the held ones follow.
  gather_leaf_triangles(b.tree, b.prims, b.scene, TriangleArrays::kEdges, reused);
  EXPECT_TRUE(reused.holds(TriangleArrays::kEdges));
  EXPECT_TRUE(reused.verts.empty());
  // Another tree of another size.
  const test::BuiltBvh small = test::build_flat({test::random_soup(100, 6)}, BuildOptions{});
  gather_leaf_triangles(small.tree, small.prims, small.scene, TriangleArrays::kBoth, reused);
  EXPECT_EQ(reused.size(), small.bvh.triangles.size());
  EXPECT_EQ(reused.refs, small.bvh.triangles.refs);
  EXPECT_EQ(std::memcmp(reused.edges.data(), small.bvh.triangles.edges.data(),
                        reused.size() * sizeof(TriangleEdges)),
            0);
}

TEST(Flatten, EmptySceneGivesEmptyLayout) {
  const test::BuiltBvh b = test::build_flat({}, BuildOptions{});
  EXPECT_TRUE(b.bvh.empty());
  EXPECT_EQ(b.bvh.memory_bytes(), 0u);
}

TEST(Flatten, MalformedTreeThrows) {
  test::BuiltBvh b = test::build_flat({test::random_soup(100, 2)}, BuildOptions{});
  BuildTree bad = b.tree;
  bad.nodes[0].right = static_cast<uint32_t>(bad.nodes.size() + 5);
  EXPECT_THROW(flatten(bad, b.prims, b.scene), std::invalid_argument);
}

}  // namespace
}  // namespace hprt
