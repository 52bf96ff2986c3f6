// The query diff's exact judges on hand-checked cases (a cube's crossings,
// through its corner and edges, inside/outside/on, nearest points), and the
// diff itself: the bvh backend against Embree is never wrong, while a
// backend that double counts (the mt test through shared edges) or whose
// parity breaks (Embree near the surface) is caught.
#include <gtest/gtest.h>

#include <limits>

#include "backends/intersector.h"
#include "core/error.h"
#include "core/parallel.h"
#include "meshgen/mesh_generators.h"
#include "validators/point_sets.h"
#include "validators/query_diff.h"
#include "validators/ray_sets.h"

namespace hprt {
namespace {

TriangleMesh cube() {
  TriangleMesh m;
  m.name = "cube";
  m.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                 {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const uint32_t f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                             {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  for (const auto& t : f) m.triangles.push_back(Vec3u{{t[0], t[1], t[2]}});
  return m;
}

Ray ray(Vec3f o, Vec3f d) {
  Ray r;
  r.org = o;
  r.dir = d;
  return r;
}

TEST(QueryDiff, ExactJudgesOnACube) {
  Scene scene;
  scene.add_mesh(cube());
  bool edge = true;
  EXPECT_EQ(exact_count(scene, ray({-5, 0.1f, 0.2f}, {1, 0, 0}), &edge), 2u);
  EXPECT_FALSE(edge);
  EXPECT_EQ(exact_count(scene, ray({0, 0, 0}, {1, 1, 1}), &edge), 1u);  // a corner: fill rule
  EXPECT_TRUE(edge);
  EXPECT_EQ(exact_count(scene, ray({-5, 3, 0}, {1, 0, 0}), &edge), 0u);
  EXPECT_EQ(exact_location(scene, {0.5f, 0.25f, 0}, 1), PointLocation::kInside);
  EXPECT_EQ(exact_location(scene, {1, 0.25f, 0}, 1), PointLocation::kOnSurface);
  EXPECT_EQ(exact_location(scene, {1, 1, 1}, 1), PointLocation::kOnSurface);
  EXPECT_EQ(exact_location(scene, {std::nextafter(1.0f, 2.0f), 0, 0}, 1), PointLocation::kOutside);
  EXPECT_EQ(exact_location(scene, {std::nextafter(1.0f, 0.0f), 0, 0}, 1), PointLocation::kInside);
  const ClosestPoint c = exact_closest(scene, {0, 0, 3}, HUGE_VALF);
  EXPECT_EQ(c.distance, 2.0f);
  EXPECT_EQ(c.point.z, 1.0f);
  EXPECT_FALSE(exact_closest(scene, {0, 0, 3}, 1.5f).found());
}

std::unique_ptr<Intersector> built_with_test(
    const Scene& scene, const std::string& backend,
    TriangleTestKind test = TriangleTestKind::kWatertight) {
  BackendOptions o;
  o.backend = backend;
  o.triangle_test = test;
  o.threads = 2;
  auto b = make_intersector(backend, o);
  b->build(scene);
  return b;
}

TEST(QueryDiff, BvhIsNeverWrongAndTheDiffCatchesWrongBackends) {
  Scene scene;
  scene.add_mesh(generate_torus(2000));
  run_with_threads(2, [&] {
    auto bvh = built_with_test(scene, "bvh");
    auto embree = built_with_test(scene, "embree");
    auto mt = built_with_test(scene, "bvh", TriangleTestKind::kMoller);
    const std::vector<Ray> probes = make_rays(scene, RayKind::kVertexProbe, 3000, 1);
    const QueryDiffResult c = run_count_diff(scene, probes, *bvh, *embree);
    EXPECT_EQ(c.backend_wrong(), 0u);
    EXPECT_GT(c.mismatches, 0u);
    EXPECT_EQ(c.unjudged, 0u);
    const QueryDiffResult m = run_count_diff(scene, probes, *mt, *bvh);
    EXPECT_GT(m.backend_wrong(), 0u);  // the mt test counts shared vertices more than once

    const std::vector<Vec3f> near = make_points(scene, PointKind::kNear, 5000, 3);
    const QueryDiffResult in = run_inside_diff(scene, near, *bvh, *embree);
    EXPECT_EQ(in.backend_wrong(), 0u);
    const QueryDiffResult swapped = run_inside_diff(scene, near, *embree, *bvh);
    EXPECT_GT(swapped.backend_wrong(), 0u);
    EXPECT_EQ(swapped.backend_wrong(), in.backend_right);

    const std::vector<Vec3f> hard = make_points(scene, PointKind::kHard, 3000, 4);
    EXPECT_EQ(run_closest_diff(scene, hard, *bvh, *embree).backend_wrong(), 0u);
    QueryDiffOptions opts;
    opts.brute_force_limit = 10;  // too small a limit: reported, not judged
    const QueryDiffResult u = run_count_diff(scene, probes, *bvh, *embree, opts);
    EXPECT_EQ(u.unjudged, u.mismatches);
    const std::string text = query_diff_summary(swapped, "embree", "bvh", "near, seed 3");
    EXPECT_NE(text.find("FAIL"), std::string::npos) << text;
  });
}

TEST(QueryDiff, PointSetsAreReproducibleAndNamed) {
  Scene scene;
  scene.add_mesh(cube());
  for (const std::string& name : point_kind_names()) {
    const PointKind k = parse_point_kind(name);
    EXPECT_EQ(to_string(k), name);
    const auto a = make_points(scene, k, 100, 9), b = make_points(scene, k, 100, 9);
    ASSERT_EQ(a.size(), 100u);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]);
  }
  EXPECT_THROW(parse_point_kind("lattice"), OptionError);
  EXPECT_THROW(make_points(Scene{}, PointKind::kRandom, 5, 1), InputError);
}

}  // namespace
}  // namespace hprt
