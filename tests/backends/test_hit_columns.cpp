// Intersector::intersect_columns on every backend: the same answers as
// intersect's records, bit for bit, from Ray records or six-float rays
// (occluded too), any subset of the columns, and each hit's normal that of
// the scene's own triangle (core/triangle_normal.h) bit for bit, zero on a
// miss: for every layout and both triangle tests, coherent rays (packets),
// single rays and several rays in flight (a tree past kInterleaveMinBytes),
// invalid rays, an empty scene, and after a refit. Only a tree without
// vertices (the mt test) keeps a leaf-order table, and counts it in
// memory_bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
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

// Rays as six floats with one [tnear, tfar] for all (RayInput, read a block
// at a time): the closest hits, occlusion, crossing counts and hit lists
// (cut at two a ray) of the same rays as records, bit for bit. The interval cuts some hits off, and
// the count (not a multiple of a group or a block) leaves a partial group at the end.
void expect_six_floats(const Intersector& isect, const Scene& scene, std::vector<Ray> rays,
                       const std::string& what) {
  rays.resize(rays.size() - 7);
  const size_t n = rays.size();
  std::vector<uint8_t> uncut(n);
  isect.occluded(rays, uncut);
  const float tnear = 0.01f, tfar = 0.5f * length(scene.bounds().diagonal());
  std::vector<float> six;
  for (Ray& r : rays) {
    six.insert(six.end(), {r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z});
    r.tnear = tnear, r.tfar = tfar;
  }
  const RayInput input(six, tnear, tfar);
  std::vector<float> t_records(n), t_six(n, 5.0f), uv_records(2 * n), uv_six(2 * n, 5.0f);
  std::vector<float> normal_records(3 * n), normal_six(3 * n, 5.0f);
  std::vector<uint32_t> prim_records(n), prim_six(n, 5);
  isect.intersect_columns(
      scene, rays,
      {t_records.data(), nullptr, prim_records.data(), uv_records.data(), normal_records.data()});
  isect.intersect_columns(
      scene, input, {t_six.data(), nullptr, prim_six.data(), uv_six.data(), normal_six.data()});
  EXPECT_EQ(std::memcmp(t_records.data(), t_six.data(), n * sizeof(float)), 0) << what;
  EXPECT_EQ(prim_records, prim_six) << what;
  EXPECT_EQ(std::memcmp(uv_records.data(), uv_six.data(), 2 * n * sizeof(float)), 0) << what;
  EXPECT_EQ(std::memcmp(normal_records.data(), normal_six.data(), 3 * n * sizeof(float)), 0)
      << what;
  std::vector<uint8_t> occluded_records(n), occluded_six(n, 5);
  isect.occluded(rays, occluded_records);
  isect.occluded(input, occluded_six);
  EXPECT_EQ(occluded_records, occluded_six) << what;
  std::vector<uint32_t> count_records(n), count_six(n, 5);
  isect.count(rays, count_records);
  isect.count(input, count_six);
  EXPECT_EQ(count_records, count_six) << what;
  HitLists all_records, all_six;
  isect.intersect_all(rays, 2, all_records);
  isect.intersect_all(input, 2, all_six);
  EXPECT_EQ(all_records.offsets, all_six.offsets) << what;
  EXPECT_EQ(all_records.truncated, all_six.truncated) << what;
  ASSERT_EQ(all_records.hits.size(), all_six.hits.size()) << what;
  EXPECT_EQ(
      std::memcmp(all_records.hits.data(), all_six.hits.data(), all_six.hits.size() * sizeof(Hit)),
      0)
      << what;
  // The interval took effect: fewer rays blocked than over [0, inf), where any are.
  const auto blocked = [](const std::vector<uint8_t>& o) {
    return size_t(std::count(o.begin(), o.end(), uint8_t{1}));
  };
  if (blocked(uncut) > 0) {
    EXPECT_LT(blocked(occluded_six), blocked(uncut)) << what;
  }
}

// Every column, then only the normals and primitive ids (the others null,
// untouched), against intersect's records. Returns how many rays hit.
size_t expect_columns(const Intersector& isect, const Scene& scene, const std::vector<Ray>& rays,
                      const std::string& what) {
  const size_t n = rays.size();
  std::vector<Hit> plain(n);
  isect.intersect(rays, plain);
  std::vector<float> t(n, 5.0f), uv(2 * n, 5.0f), normals(3 * n, 5.0f), only_normals(3 * n, 5.0f);
  std::vector<uint32_t> geom(n, 5), prim(n, 5), only_prim(n, 5);
  isect.intersect_columns(scene, rays,
                          {t.data(), geom.data(), prim.data(), uv.data(), normals.data()});
  isect.intersect_columns(scene, rays,
                          {nullptr, nullptr, only_prim.data(), nullptr, only_normals.data()});
  size_t hit_count = 0;
  for (size_t i = 0; i < n; ++i) {
    const Hit column{t[i], uv[2 * i], uv[2 * i + 1], geom[i], prim[i]};
    if (std::memcmp(&column, &plain[i], sizeof(Hit)) != 0 || only_prim[i] != plain[i].prim_id) {
      ADD_FAILURE() << what << " ray " << i << ": column t " << column.t << " prim "
                    << column.prim_id << ", record t " << plain[i].t << " prim "
                    << plain[i].prim_id;
      break;
    }
    float want[3] = {0.0f, 0.0f, 0.0f};
    if (plain[i].hit()) {
      triangle_normal(scene.meshes[plain[i].geom_id], plain[i].prim_id, want);
      ++hit_count;
    }
    const float* got = &normals[3 * i];
    if (std::memcmp(got, want, sizeof want) != 0 ||
        std::memcmp(&only_normals[3 * i], want, sizeof want) != 0) {
      ADD_FAILURE() << what << " ray " << i << ": " << got[0] << " " << got[1] << " " << got[2]
                    << ", want " << want[0] << " " << want[1] << " " << want[2];
      break;
    }
  }
  expect_six_floats(isect, scene, rays, what);
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

TEST(HitColumns, EveryLayoutBothTestsAndEmbreeGiveTheTrianglesOwnBits) {
  const Scene scene =
      test::scene_of({test::random_soup(20000, 5, 0.03f), test::icosphere(4), test::grid(20, 20)});
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
        EXPECT_GT(expect_columns(*isect, scene, rays, what), rays.size() / 10) << what;
        // The table: only where the tree has no vertices, 12 bytes a triangle.
        const size_t table = kind == TriangleTestKind::kMoller ? 12 * scene.triangle_count() : 0;
        EXPECT_EQ(isect->info().memory_bytes, before + table) << what;
        return 0;
      });
    }
  run_with_threads(2, [&] {
    auto embree = make_intersector("embree", BackendOptions{});
    embree->build(scene);
    EXPECT_GT(expect_columns(*embree, scene, rays, "embree"), rays.size() / 10);
    return 0;
  });
}

TEST(HitColumns, SeveralRaysInFlightOnATreeFromMemory) {
  const Scene scene = test::scene_of({generate_sphere(300000)});
  const std::vector<Ray> rays = mixed_rays(scene.bounds(), 20000);
  for (const TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller}) {
    BackendOptions o;
    o.triangle_test = kind;
    auto isect = make_intersector("bvh", o);
    isect->build(scene);
    // Past the size from which batches interleave (trace_batch.h), whichever
    // arrays the test keeps.
    ASSERT_GE(isect->info().memory_bytes, kInterleaveMinBytes);
    EXPECT_GT(expect_columns(*isect, scene, rays, isect->info().name), rays.size() / 10);
  }
}

TEST(HitColumns, FollowARefitAndARebuild) {
  Scene scene = test::scene_of({test::icosphere(4), test::random_soup(5000, 3, 0.05f)});
  const std::vector<Ray> rays = mixed_rays(scene.bounds(), 4000);
  for (const TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller})
    for (const UpdateStrategy update : {UpdateStrategy::kRefit, UpdateStrategy::kRebuild}) {
      BackendOptions o;
      o.triangle_test = kind;
      o.update = update;
      auto isect = make_intersector("bvh", o);
      Scene s = scene;
      isect->build(s);
      expect_columns(*isect, s, rays, "built");
      for (Vec3f& p : s.meshes[0].positions)
        p = p + Vec3f{0.2f * std::sin(5 * p.y), 0.1f * p.z, 0.0f};
      isect->update(s);
      EXPECT_EQ(isect->info().rebuilt, update == UpdateStrategy::kRebuild);
      EXPECT_GT(expect_columns(*isect, s, rays, isect->info().name + " updated"), rays.size() / 10);
    }
}

TEST(HitColumns, EmptySceneMisses) {
  const Scene empty;
  const std::vector<Ray> rays = test::random_rays(AABB{Vec3f(-1.0f), Vec3f(1.0f)}, 50, 3);
  for (const char* backend : {"bvh", "embree"}) {
    auto isect = make_intersector(backend, BackendOptions{});
    isect->build(empty);
    EXPECT_EQ(expect_columns(*isect, empty, rays, backend), 0u);
  }
}

}  // namespace
}  // namespace hprt
