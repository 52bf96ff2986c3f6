// The wide layouts (--layout bvh4|bvh8): flatten_wide gives nodes whose slot
// boxes are exactly their contents, at least two children per node, the same
// leaf-order triangles as the binary layout, the binary tree's SAH cost (via
// the collapsed inner nodes), and compact trees (far fewer nodes); traversal
// matches brute force exactly as the binary traversal does (same t bit for
// bit, the primitive up to ties, occlusion = a hit exists) and finds the
// same hits as the binary layout of the same build.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "bvh/layout/flatten_wide.h"
#include "bvh/refit/refit_bvh2.h"
#include "bvh/refit/refit_wide.h"
#include "bvh/traverse/traverse_wide.h"
#include "core/tree_stats.h"
#include "tests/support/bvh_trace_helpers.h"
#include "tests/support/wide_bvh_checks.h"

namespace hprt {
namespace {

template <int N>
void check_layout(const test::BuiltBvh& b) {
  const WideBvh<N> w = flatten_wide<N>(b.tree, b.prims, b.scene);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(w.nodes.data()) % 64, 0u);
  ASSERT_EQ(test::check_wide(w, b.scene), "");
  ASSERT_EQ(w.nodes.size(), w.collapsed.size());
  // Same leaf order and triangle data as the binary layout.
  ASSERT_EQ(w.triangles.size(), b.bvh.triangles.size());
  for (size_t k = 0; k < w.triangles.size(); ++k) {
    ASSERT_EQ(w.triangles.refs[k], b.bvh.triangles.refs[k]);
    ASSERT_EQ(w.triangles.edges[k].e2, b.bvh.triangles.edges[k].e2);
  }
  // Each wide node stands for 1 + collapsed.count binary inner nodes, and
  // together they are all of them.
  const size_t binary_inner = (b.tree.nodes.size() - 1) / 2;
  size_t covered = 0;
  for (const CollapsedInner<N>& c : w.collapsed) covered += 1 + c.count;
  EXPECT_EQ(covered, binary_inner);
  if (binary_inner >= 64) {
    EXPECT_LT(double(w.nodes.size()), double(binary_inner) * (N == 8 ? 0.25 : 0.5));
  }
  // Free slots only where every leaf of the node holds one triangle; the
  // binary leaves split over slots are recorded as contiguous ranges of leaf
  // slots, so the wide leaf slots less those splits are the binary leaves.
  size_t leaf_slots = 0, split_parts = 0;
  for (size_t w_i = 0; w_i < w.nodes.size(); ++w_i) {
    const WideNode<N>& n = w.nodes[w_i];
    const CollapsedInner<N>& c = w.collapsed[w_i];
    int used = 0;
    uint32_t largest_leaf = 0;
    for (int i = 0; i < N; ++i) {
      if (n.child[i].empty()) continue;
      ++used;
      if (n.child[i].is_leaf()) {
        ++leaf_slots;
        largest_leaf = std::max(largest_leaf, n.child[i].count());
      }
    }
    if (used < N) {
      EXPECT_LE(largest_leaf, 1u) << "node " << w_i;
    }
    for (int r = 0; r < c.split_leaves; ++r) {
      ASSERT_GE(c.leaf_end[r] - c.leaf_begin[r], 2);
      for (int i = c.leaf_begin[r]; i < c.leaf_end[r]; ++i) {
        ASSERT_TRUE(n.child[i].is_leaf());
        if (i > c.leaf_begin[r]) {
          EXPECT_EQ(n.child[i].index(), n.child[i - 1].index() + n.child[i - 1].count());
        }
      }
      split_parts += size_t(c.leaf_end[r] - c.leaf_begin[r]) - 1;
    }
  }
  const size_t binary_leaves = b.tree.nodes.size() - binary_inner;
  if (w.root.is_inner()) {
    EXPECT_EQ(leaf_slots - split_parts, binary_leaves);
  }
  const double sah = compute_tree_stats(b.tree, b.prims).sah_cost;
  EXPECT_NEAR(wide_sah_cost(w), sah, 1e-12 * sah);
  EXPECT_EQ(w.memory_bytes(), w.nodes.size() * sizeof(WideNode<N>) + w.triangles.memory_bytes());
  // The node pass alone (what the backend runs beside the triangle pass)
  // gives the same nodes, byte for byte, and no triangles.
  const WideBvh<N> nodes_only = flatten_wide_nodes<N>(b.tree, b.prims, b.scene);
  EXPECT_TRUE(nodes_only.triangles.refs.empty());
  EXPECT_EQ(nodes_only.root.bits, w.root.bits);
  ASSERT_EQ(nodes_only.nodes.size(), w.nodes.size());
  EXPECT_EQ(
      std::memcmp(nodes_only.nodes.data(), w.nodes.data(), w.nodes.size() * sizeof(WideNode<N>)),
      0);
  // And so do prim infos whose boxes are released (the backend's: the boxes
  // of split leaves' parts then come from the scene).
  PrimInfo released = b.prims;
  released.release_bounds();
  const WideBvh<N> from_scene = flatten_wide_nodes<N>(b.tree, released, b.scene);
  ASSERT_EQ(from_scene.nodes.size(), w.nodes.size());
  EXPECT_EQ(
      std::memcmp(from_scene.nodes.data(), w.nodes.data(), w.nodes.size() * sizeof(WideNode<N>)),
      0);
  ASSERT_EQ(nodes_only.collapsed.size(), w.collapsed.size());
  for (size_t k = 0; k < w.collapsed.size(); ++k) {
    EXPECT_EQ(nodes_only.collapsed[k].count, w.collapsed[k].count);
    EXPECT_EQ(std::memcmp(nodes_only.collapsed[k].begin, w.collapsed[k].begin, N - 2), 0);
    EXPECT_EQ(std::memcmp(nodes_only.collapsed[k].end, w.collapsed[k].end, N - 2), 0);
    EXPECT_EQ(nodes_only.collapsed[k].split_leaves, w.collapsed[k].split_leaves);
    EXPECT_EQ(std::memcmp(nodes_only.collapsed[k].leaf_begin, w.collapsed[k].leaf_begin, N / 2), 0);
    EXPECT_EQ(std::memcmp(nodes_only.collapsed[k].leaf_end, w.collapsed[k].leaf_end, N / 2), 0);
  }
}

TEST(FlattenWide, SlotsExactAndSahKeptForEveryBuilderAndLeafSize) {
  const TriangleMesh soup = test::random_soup(3000, 21, 0.05f);
  for (BuilderKind builder :
       {BuilderKind::kSweep, BuilderKind::kBinned, BuilderKind::kParallel, BuilderKind::kMorton})
    for (int leaf : {1, 2, 4, 8}) {
      SCOPED_TRACE(std::string(to_string(builder)) + " leaf " + std::to_string(leaf));
      BuildOptions o;
      o.builder = builder;
      o.max_leaf_size = leaf;
      const test::BuiltBvh b =
          test::build_flat({soup, test::icosphere(3), test::with_invalid_triangles()}, o);
      check_layout<4>(b);
      check_layout<8>(b);
    }
}

TEST(FlattenWide, EmptySingleLeafAndMalformedTrees) {
  const test::BuiltBvh none = test::build_flat({}, BuildOptions{});
  EXPECT_TRUE(flatten_wide<8>(none.tree, none.prims, none.scene).empty());
  TriangleMesh one;
  test::add_triangle(one, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const test::BuiltBvh single = test::build_flat({one}, BuildOptions{});
  const WideBvh<8> w = flatten_wide<8>(single.tree, single.prims, single.scene);
  EXPECT_TRUE(w.root.is_leaf());
  EXPECT_TRUE(w.nodes.empty());
  EXPECT_EQ(wide_sah_cost(w), 1.0);
  Ray r;
  r.org = {0.2f, 0.2f, 1.0f};
  r.dir = {0, 0, -1};
  Hit h;
  EXPECT_TRUE((traverse_wide<WatertightTest, false>(w, r, h)));
  EXPECT_EQ(h.t, 1.0f);

  const test::BuiltBvh b = test::build_flat({test::random_soup(200, 3)}, BuildOptions{});
  BuildTree bad = b.tree;
  bad.nodes[0].right = 0;  // child index not after its parent
  EXPECT_THROW(flatten_wide<8>(bad, b.prims, b.scene), std::invalid_argument);
  bad = b.tree;
  bad.nodes[0].right = 1;  // both children the same subtree (a DAG)
  EXPECT_THROW(flatten_wide<4>(bad, b.prims, b.scene), std::invalid_argument);
  bad = b.tree;
  for (BuildNode& n : bad.nodes)
    if (n.is_leaf()) n.first = uint32_t(bad.prim_order.size());  // leaf past prim_order
  EXPECT_THROW(flatten_wide<8>(bad, b.prims, b.scene), std::invalid_argument);
}

template <typename Test, int N>
void expect_same_as_brute_force_and_binary(const test::BuiltBvh& b, const WideBvh<N>& w,
                                           const std::vector<Ray>& rays, const char* what) {
  size_t hits = 0, ties = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    Hit bh, wh, oh, fh;
    const bool bf = test::brute_force<Test>(b.bvh, rays[i], bh);
    const bool tr = traverse_wide<Test, false>(w, rays[i], wh);
    const bool oc = traverse_wide<Test, true>(w, rays[i], oh);
    const bool fl = traverse<Test, false>(b.bvh, rays[i], fh);
    ASSERT_EQ(bf, tr) << what << " ray " << i;
    ASSERT_EQ(bf, oc) << what << " ray " << i;
    ASSERT_EQ(bf, fl) << what << " ray " << i;
    if (!bf) {
      EXPECT_FALSE(wh.hit());
      continue;
    }
    ++hits;
    ASSERT_EQ(bh.t, wh.t) << what << " ray " << i;
    ASSERT_EQ(fh.t, wh.t) << what << " ray " << i;
    if (bh.prim_id != wh.prim_id) {
      ++ties;
    } else {
      EXPECT_EQ(bh.u, wh.u);
      EXPECT_EQ(bh.v, wh.v);
    }
    EXPECT_EQ(bh.geom_id, wh.geom_id);
  }
  EXPECT_GT(hits, rays.size() / 20) << what;
  EXPECT_LE(ties, hits / 10 + 5) << what;
}

template <typename Test>
void check_traversal(const TriangleMesh& mesh, int leaf, BuilderKind builder, uint64_t seed) {
  BuildOptions o;
  o.builder = builder;
  o.max_leaf_size = leaf;
  const test::BuiltBvh b = test::build_flat({mesh}, o);
  const AABB box = b.scene.bounds();
  const auto random = test::random_rays(box, 1500, seed);
  const auto coherent = test::coherent_rays(box, 40, 30);
  const WideBvh<4> w4 = flatten_wide<4>(b.tree, b.prims, b.scene);
  const WideBvh<8> w8 = flatten_wide<8>(b.tree, b.prims, b.scene);
  expect_same_as_brute_force_and_binary<Test>(b, w4, random, "bvh4 random");
  expect_same_as_brute_force_and_binary<Test>(b, w4, coherent, "bvh4 coherent");
  expect_same_as_brute_force_and_binary<Test>(b, w8, random, "bvh8 random");
  expect_same_as_brute_force_and_binary<Test>(b, w8, coherent, "bvh8 coherent");
}

// A tree of tens of thousands of nodes: the collapse plan is solved in
// parallel over subtrees below a cut near the root, the nodes filled in
// parallel; the layout is still exact, and a node deep below the cut whose
// right child lies in another subtree is a malformed tree.
TEST(FlattenWide, LargeTreeSolvedInParallelSubtrees) {
  const test::BuiltBvh b = test::build_flat({test::random_soup(120000, 5, 0.02f)}, BuildOptions{});
  ASSERT_GT(b.tree.nodes.size(), 16u * 4096u);
  check_layout<4>(b);
  check_layout<8>(b);
  const WideBvh<8> w = flatten_wide<8>(b.tree, b.prims, b.scene);
  expect_same_as_brute_force_and_binary<WatertightTest>(
      b, w, test::random_rays(b.scene.bounds(), 400, 17), "large bvh8 random");

  BuildTree bad = b.tree;
  const uint32_t deep = 10;  // ten levels down the left spine (left child = index + 1)
  ASSERT_FALSE(bad.nodes[deep].is_leaf());
  bad.nodes[deep].right = b.tree.nodes[0].right;  // the root's right subtree
  EXPECT_THROW(flatten_wide<8>(bad, b.prims, b.scene), std::invalid_argument);
}

TEST(TraverseWide, MatchesBruteForceOnSoupsAllLeafSizes) {
  const TriangleMesh soup = test::random_soup(3000, 11, 0.05f);
  for (int leaf = 1; leaf <= 8; ++leaf) {
    SCOPED_TRACE(leaf);
    check_traversal<WatertightTest>(soup, leaf, BuilderKind::kBinned, 100 + leaf);
    check_traversal<MollerTest>(soup, leaf, BuilderKind::kParallel, 200 + leaf);
  }
}

TEST(TraverseWide, MatchesBruteForceOnGridAndSphere) {
  for (int leaf : {1, 4, 8}) {
    SCOPED_TRACE(leaf);
    check_traversal<WatertightTest>(test::grid(40, 40), leaf, BuilderKind::kParallel, 7);
    check_traversal<MollerTest>(test::icosphere(4), leaf, BuilderKind::kSweep, 9);
  }
}

TEST(TraverseWide, IntervalLimitsEmptyTreeAndStats) {
  const test::BuiltBvh b = test::build_flat({test::grid(8, 8)}, BuildOptions{});
  const WideBvh<8> w = flatten_wide<8>(b.tree, b.prims, b.scene);
  Ray ray;
  ray.org = {0.3f, 0.6f, 1.0f};
  ray.dir = {0, 0, -1};
  Hit h;
  ASSERT_TRUE((traverse_wide<WatertightTest, false>(w, ray, h)));
  ray.tfar = h.t;  // t <= tfar: still a hit
  EXPECT_TRUE((traverse_wide<WatertightTest, false>(w, ray, h)));
  ray.tfar = std::nextafter(h.t, 0.0f);
  EXPECT_FALSE((traverse_wide<WatertightTest, false>(w, ray, h)));
  ray.tfar = std::numeric_limits<float>::infinity();
  ASSERT_TRUE((traverse_wide<MollerTest, false>(w, ray, h)));  // its own t
  ray.tfar = std::nextafter(h.t, 0.0f);
  EXPECT_FALSE((traverse_wide<MollerTest, true>(w, ray, h)));
  EXPECT_FALSE((traverse_wide<WatertightTest, false>(WideBvh<4>{}, ray, h)));

  const test::BuiltBvh s = test::build_flat({test::random_soup(2000, 3)}, BuildOptions{});
  const WideBvh<8> ws = flatten_wide<8>(s.tree, s.prims, s.scene);
  TraversalStats wide_stats, binary_stats;
  for (const Ray& r : test::random_rays(s.scene.bounds(), 200, 4)) {
    Hit a, c;
    traverse_wide<WatertightTest, false, 8, true>(ws, r, a, &wide_stats);
    traverse<WatertightTest, false, true>(s.bvh, r, c, &binary_stats);
  }
  EXPECT_GT(wide_stats.nodes, 200u);
  EXPECT_LT(wide_stats.nodes, binary_stats.nodes);  // fewer, wider steps
  EXPECT_LT(wide_stats.triangles, 200u * 2000u / 4);
}

}  // namespace
}  // namespace hprt
