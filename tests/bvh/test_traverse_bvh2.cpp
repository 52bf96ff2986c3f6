// Traversal against brute force: the closest t is bit-identical (same
// triangle test on the same data), the primitive the same up to ties, and
// occlusion equals "a closest hit exists", over soups, grids and spheres,
// random and coherent rays, leaf sizes 1..8, both triangle tests.
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

template <typename Test>
void expect_matches_brute_force(const test::BuiltBvh& b, const std::vector<Ray>& rays,
                                const char* what) {
  size_t hits = 0, ties = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    Hit bh, th, oh;
    const bool bf = test::brute_force<Test>(b.bvh, rays[i], bh);
    const bool tr = traverse<Test, false>(b.bvh, rays[i], th);
    const bool oc = traverse<Test, true>(b.bvh, rays[i], oh);
    ASSERT_EQ(bf, tr) << what << " ray " << i;
    ASSERT_EQ(bf, oc) << what << " ray " << i;
    if (!bf) {
      EXPECT_FALSE(th.hit());
      continue;
    }
    ++hits;
    ASSERT_EQ(bh.t, th.t) << what << " ray " << i;
    if (bh.prim_id != th.prim_id) {
      ++ties;
    } else {
      EXPECT_EQ(bh.u, th.u);
      EXPECT_EQ(bh.v, th.v);
    }
    EXPECT_EQ(bh.geom_id, th.geom_id);
  }
  EXPECT_GT(hits, rays.size() / 20) << what;  // the sets really hit something
  EXPECT_LE(ties, hits / 10 + 5) << what;
}

template <typename Test>
void check_mesh(const TriangleMesh& mesh, int leaf_size, BuilderKind builder, uint64_t seed) {
  BuildOptions o;
  o.builder = builder;
  o.max_leaf_size = leaf_size;
  const test::BuiltBvh b = test::build_flat({mesh}, o);
  const AABB box = b.scene.bounds();
  expect_matches_brute_force<Test>(b, test::random_rays(box, 1500, seed), "random");
  expect_matches_brute_force<Test>(b, test::coherent_rays(box, 40, 30), "coherent");
}

TEST(Traverse, MatchesBruteForceOnSoupsAllLeafSizes) {
  const TriangleMesh soup = test::random_soup(3000, 11, 0.05f);
  for (int leaf = 1; leaf <= 8; ++leaf) {
    SCOPED_TRACE(leaf);
    check_mesh<WatertightTest>(soup, leaf, BuilderKind::kBinned, 100 + leaf);
    check_mesh<MollerTest>(soup, leaf, BuilderKind::kParallel, 200 + leaf);
  }
}

TEST(Traverse, MatchesBruteForceOnGridAndSphere) {
  const TriangleMesh g = test::grid(40, 40);
  const TriangleMesh s = test::icosphere(4);
  for (int leaf : {1, 4, 8}) {
    SCOPED_TRACE(leaf);
    check_mesh<WatertightTest>(g, leaf, BuilderKind::kParallel, 7);
    check_mesh<MollerTest>(g, leaf, BuilderKind::kSweep, 8);
    check_mesh<WatertightTest>(s, leaf, BuilderKind::kPresorted, 9);
    check_mesh<MollerTest>(s, leaf, BuilderKind::kBinned, 10);
  }
}

TEST(Traverse, RaysFromInsideAClosedSphereAlwaysHit) {
  const test::BuiltBvh b = test::build_flat({test::icosphere(3)}, BuildOptions{});
  test::Rng r(5);
  for (int i = 0; i < 2000; ++i) {
    Ray ray;
    ray.org = Vec3f{r.uniform(), r.uniform(), r.uniform()} * 0.5f - Vec3f{0.25f};
    ray.dir = test::random_direction(r);
    Hit h;
    ASSERT_TRUE((traverse<WatertightTest, false>(b.bvh, ray, h))) << i;
    EXPECT_GT(h.t, 0.0f);
  }
}

TEST(Traverse, IntervalLimitsAndEmptyTree) {
  const test::BuiltBvh b = test::build_flat({test::grid(8, 8)}, BuildOptions{});
  Ray ray;
  ray.org = {0.3f, 0.6f, 1.0f};
  ray.dir = {0, 0, -1};
  Hit h;
  ASSERT_TRUE((traverse<WatertightTest, false>(b.bvh, ray, h)));
  const float t = h.t;
  ray.tfar = t;  // t <= tfar: still a hit
  EXPECT_TRUE((traverse<WatertightTest, false>(b.bvh, ray, h)));
  ray.tfar = std::nextafter(t, 0.0f);
  EXPECT_FALSE((traverse<WatertightTest, false>(b.bvh, ray, h)));
  EXPECT_FALSE((traverse<WatertightTest, true>(b.bvh, ray, h)));
  const Bvh2 empty;
  ray.tfar = 100.0f;
  EXPECT_FALSE((traverse<WatertightTest, false>(empty, ray, h)));
  EXPECT_FALSE((traverse<MollerTest, true>(empty, ray, h)));
}

TEST(Traverse, StatsCountWork) {
  const test::BuiltBvh b = test::build_flat({test::random_soup(2000, 3)}, BuildOptions{});
  TraversalStats stats;
  size_t hits = 0;
  for (const Ray& r : test::random_rays(b.scene.bounds(), 200, 4)) {
    Hit h;
    hits += traverse<WatertightTest, false, true>(b.bvh, r, h, &stats);
  }
  EXPECT_GT(hits, 0u);
  EXPECT_GT(stats.nodes, 200u);
  EXPECT_GT(stats.triangles, hits);
  EXPECT_LT(stats.triangles, 200u * 2000u / 4);  // far fewer tests than brute force
}

}  // namespace
}  // namespace hprt
