// Intersector::intersect_normals on every backend: the same hits as
// intersect, bit for bit, and each hit's normal that of the scene's own
// triangle (core/triangle_normal.h) bit for bit, zero on a miss: for every
// layout and both triangle tests, coherent rays (packets), single rays and
// several rays in flight (a tree past kInterleaveMinBytes), invalid rays, an
// empty scene, and after a refit. Only a tree without vertices (the mt test)
// keeps a leaf-order table, and counts it in memory_bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "bvh/traverse/trace_batch.h"
#include "core/parallel.h"
#include "core/triangle_normal.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

Scene scene_of(std::vector<TriangleMesh> meshes) {
  Scene s;
  for (auto& m : meshes) s.add_mesh(std::move(m));
  return s;
}

// Random rays, a pinhole grid (whole coherent groups of 16: packets), and
// some invalid ones.
std::vector<Ray> mixed_rays(const AABB& box, size_t n) {
  std::vector<Ray> rays = test::random_rays(box, n, 19);
  const std::vector<Ray> camera = test::coherent_rays(box, 48, 32);
  rays.insert(rays.end(), camera.begin(), camera.end());
  for (size_t i = 0; i < n; i += 97) rays[i].dir = Vec3f(0.0f);
  for (size_t i = 5; i < n; i += 101) rays[i].org.x = std::numeric_limits<float>::quiet_NaN();
  return rays;
}

// Returns how many rays hit.
size_t expect_normals(const Intersector& isect, const Scene& scene, const std::vector<Ray>& rays,
                      const std::string& what) {
  std::vector<Hit> plain(rays.size()), hits(rays.size());
  std::vector<float> normals(3 * rays.size(), 5.0f);
  isect.intersect(rays, plain);
  isect.intersect_normals(scene, rays, hits, normals);
  size_t hit_count = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(std::memcmp(&hits[i], &plain[i], sizeof(Hit)), 0) << what << " ray " << i;
    float want[3] = {0.0f, 0.0f, 0.0f};
    if (hits[i].hit()) {
      triangle_normal(scene.meshes[hits[i].geom_id], hits[i].prim_id, want);
      ++hit_count;
    }
    const float* n = &normals[3 * i];
    if (std::memcmp(n, want, sizeof want) != 0) {
      ADD_FAILURE() << what << " ray " << i << ": " << n[0] << " " << n[1] << " " << n[2]
                    << ", want " << want[0] << " " << want[1] << " " << want[2];
      break;
    }
  }
  return hit_count;
}

TEST(TriangleNormal, UnitCrossOfTheEdgesInDoubleZeroWhenDegenerate) {
  const float a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
  float n[3];
  unit_normal(a, b, c, n);
  EXPECT_EQ(n[0], 0.0f);
  EXPECT_EQ(n[1], 0.0f);
  EXPECT_EQ(n[2], 1.0f);
  unit_normal(a, c, b, n);  // the other orientation
  EXPECT_EQ(n[2], -1.0f);
  // Coordinates whose float cross product overflows (1e25^2) and a sliver
  // whose edges nearly cancel: double keeps both exact enough.
  const float big_a[3] = {1e25f, 0, 0}, big_b[3] = {-1e25f, 0, 0}, big_c[3] = {0, 0, 3e25f};
  unit_normal(big_a, big_b, big_c, n);
  EXPECT_EQ(n[0], 0.0f);
  EXPECT_EQ(n[1], 1.0f);
  EXPECT_EQ(n[2], 0.0f);
  const float s_a[3] = {0, 0, 0}, s_b[3] = {1, 1e-7f, 0}, s_c[3] = {2, 0, 1e-7f};
  unit_normal(s_a, s_b, s_c, n);
  EXPECT_NEAR(std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]), 1.0,
              1e-7);
  const float line_c[3] = {2, 0, 0};
  unit_normal(a, b, line_c, n);
  EXPECT_TRUE(n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f);
}

TEST(HitNormals, EveryLayoutBothTestsAndEmbreeGiveTheTrianglesOwnBits) {
  const Scene scene =
      scene_of({test::random_soup(20000, 5, 0.03f), test::icosphere(4), test::grid(20, 20)});
  const std::vector<Ray> rays = mixed_rays(scene.bounds(), 8000);
  for (const TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller})
    for (const BvhLayout layout : {BvhLayout::kBvh2, BvhLayout::kBvh4, BvhLayout::kBvh8}) {
      BackendOptions o;
      o.triangle_test = kind;
      o.layout = layout;
      run_with_threads(2, [&] {
        auto isect = make_intersector("bvh", o);
        isect->build(scene);
        const size_t before = isect->info().memory_bytes;
        const std::string what = isect->info().name;
        EXPECT_GT(expect_normals(*isect, scene, rays, what), rays.size() / 10) << what;
        // The table: only where the tree has no vertices, 12 bytes a triangle.
        const size_t table = kind == TriangleTestKind::kMoller ? 12 * scene.triangle_count() : 0;
        EXPECT_EQ(isect->info().memory_bytes, before + table) << what;
        return 0;
      });
    }
  run_with_threads(2, [&] {
    auto embree = make_intersector("embree", BackendOptions{});
    embree->build(scene);
    EXPECT_GT(expect_normals(*embree, scene, rays, "embree"), rays.size() / 10);
    return 0;
  });
}

TEST(HitNormals, SeveralRaysInFlightOnATreeFromMemory) {
  const Scene scene = scene_of({generate_sphere(300000)});
  const std::vector<Ray> rays = mixed_rays(scene.bounds(), 20000);
  for (const TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller}) {
    BackendOptions o;
    o.triangle_test = kind;
    auto isect = make_intersector("bvh", o);
    isect->build(scene);
    // Past the size from which batches interleave (trace_batch.h), whichever
    // arrays the test keeps.
    ASSERT_GE(isect->info().memory_bytes, kInterleaveMinBytes);
    EXPECT_GT(expect_normals(*isect, scene, rays, isect->info().name), rays.size() / 10);
  }
}

TEST(HitNormals, FollowARefitAndARebuild) {
  Scene scene = scene_of({test::icosphere(4), test::random_soup(5000, 3, 0.05f)});
  const std::vector<Ray> rays = mixed_rays(scene.bounds(), 4000);
  for (const TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller})
    for (const UpdateStrategy update : {UpdateStrategy::kRefit, UpdateStrategy::kRebuild}) {
      BackendOptions o;
      o.triangle_test = kind;
      o.update = update;
      auto isect = make_intersector("bvh", o);
      Scene s = scene;
      isect->build(s);
      expect_normals(*isect, s, rays, "built");
      for (Vec3f& p : s.meshes[0].positions)
        p = p + Vec3f{0.2f * std::sin(5 * p.y), 0.1f * p.z, 0.0f};
      isect->update(s);
      EXPECT_EQ(isect->info().rebuilt, update == UpdateStrategy::kRebuild);
      EXPECT_GT(expect_normals(*isect, s, rays, isect->info().name + " updated"), rays.size() / 10);
    }
}

TEST(HitNormals, EmptySceneMissesAndTooFewSlotsThrow) {
  const Scene empty;
  const std::vector<Ray> rays = test::random_rays(AABB{Vec3f(-1.0f), Vec3f(1.0f)}, 50, 3);
  for (const char* backend : {"bvh", "embree"}) {
    auto isect = make_intersector(backend, BackendOptions{});
    isect->build(empty);
    EXPECT_EQ(expect_normals(*isect, empty, rays, backend), 0u);
    std::vector<Hit> hits(rays.size());
    std::vector<float> normals(3 * rays.size() - 1);
    EXPECT_THROW(isect->intersect_normals(empty, rays, hits, normals), std::invalid_argument)
        << backend;
  }
}

}  // namespace
}  // namespace hprt
