// The point queries (Intersector::locate and closest) on every layout,
// against references that do not share their traversal:
//  - inside on a subdivided cube, whose answer is known in closed form, for
//    every point of a grid through it that lies on its vertex, edge and face
//    planes (and exactly on its faces);
//  - inside on an icosphere and a torus against the exact judge of
//    validators/query_diff.h (the arbiter's parity along random rays,
//    redrawn until one passes no edge or vertex exactly) for the "hard"
//    point set: points on vertex planes, on the vertices and one ulp beside;
//  - closest against the brute-force search over every triangle (the same
//    double formula: every field equal), with and without a maximum
//    distance; Embree's rtcPointQuery beside it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "backends/intersector.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/splitmix64.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/bvh_test_meshes.h"
#include "validators/point_sets.h"
#include "validators/query_diff.h"

namespace hprt {
namespace {

constexpr BvhLayout kLayouts[] = {BvhLayout::kBvh2, BvhLayout::kBvh4, BvhLayout::kBvh8};

std::unique_ptr<Intersector> built(const Scene& scene, const std::string& backend,
                                   BvhLayout layout = BvhLayout::kBvh8,
                                   BuilderKind builder = BuilderKind::kParallel,
                                   int max_leaf_size = 4) {
  BackendOptions o;
  o.backend = backend;
  o.layout = layout;
  o.build.builder = builder;
  o.build.max_leaf_size = max_leaf_size;
  // Large leaves asked for are filled: nodes made costly.
  if (max_leaf_size > 4) o.build.sah.traversal_cost = 100.0f;
  o.threads = 2;
  auto b = make_intersector(backend, o);
  b->build(scene);
  return b;
}

// The cube [-1, 1]^3, each face an n x n grid of squares cut along a
// diagonal (alternating), vertices shared: closed, coordinates exact.
TriangleMesh subdivided_cube(int n) {
  TriangleMesh m;
  m.name = "cube";
  std::map<std::array<int, 3>, uint32_t> ids;
  const auto vertex = [&](std::array<int, 3> g) {
    auto [it, added] = ids.emplace(g, uint32_t(m.positions.size()));
    if (added)
      m.positions.push_back(Vec3f{-1.0f + 2.0f * float(g[0]) / float(n),
                                  -1.0f + 2.0f * float(g[1]) / float(n),
                                  -1.0f + 2.0f * float(g[2]) / float(n)});
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side <= 1; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const auto at = [&](int a, int b) {
            std::array<int, 3> g{};
            g[axis] = side * n;
            g[u] = a;
            g[v] = b;
            return vertex(g);
          };
          const uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
          if ((i + j) % 2 == 0) {
            m.triangles.push_back(Vec3u{{a, b, c}});
            m.triangles.push_back(Vec3u{{a, c, d}});
          } else {
            m.triangles.push_back(Vec3u{{a, b, d}});
            m.triangles.push_back(Vec3u{{b, c, d}});
          }
        }
    }
  return m;
}

TEST(PointQueries, InsideExactOnEveryGridPointOfASubdividedCube) {
  Scene scene;
  scene.add_mesh(subdivided_cube(8));
  // Steps of 1/16 from -1.25 to 1.25: every vertex plane, edge line, face
  // and the midpoints between them.
  std::vector<Vec3f> points;
  std::vector<PointLocation> expected;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j)
      for (int k = -20; k <= 20; ++k) {
        points.push_back(Vec3f{float(i) / 16.0f, float(j) / 16.0f, float(k) / 16.0f});
        const int m = std::max({std::abs(i), std::abs(j), std::abs(k)});
        expected.push_back(m < 16
                               ? PointLocation::kInside
                               : (m == 16 ? PointLocation::kOnSurface : PointLocation::kOutside));
      }
  // Leaves of up to 4 and of up to 16 triangles (the on-surface test takes
  // a leaf's triangles 8 at a time).
  for (BvhLayout layout : kLayouts)
    for (const int leaf_size : {4, 16}) {
      SCOPED_TRACE(std::string(to_string(layout)) + " leaves <= " + std::to_string(leaf_size));
      run_with_threads(2, [&] {
        auto b = built(scene, "bvh", layout, BuilderKind::kParallel, leaf_size);
        std::vector<PointLocation> got(points.size());
        b->locate(points, got);
        size_t wrong = 0;
        for (size_t i = 0; i < points.size(); ++i) {
          wrong += got[i] != expected[i];
          if (got[i] != expected[i] && wrong < 5)
            ADD_FAILURE() << "point (" << points[i].x << ", " << points[i].y << ", " << points[i].z
                          << "): got " << int(got[i]) << ", expected " << int(expected[i]);
        }
        EXPECT_EQ(wrong, 0u);
      });
    }
}

TEST(PointQueries, InsideMatchesTheArbiterOnCurvedClosedMeshes) {
  const TriangleMesh meshes[] = {test::icosphere(2), generate_torus(600)};
  for (const TriangleMesh& mesh : meshes) {
    SCOPED_TRACE(mesh.name);
    Scene scene;
    scene.add_mesh(mesh);
    const std::vector<Vec3f> points = make_points(scene, PointKind::kHard, 1000, 17);
    std::vector<PointLocation> expected;
    size_t on_surface = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      expected.push_back(exact_location(scene, points[i], 23 + i));
      on_surface += expected.back() == PointLocation::kOnSurface;
    }
    EXPECT_GE(on_surface, points.size() / 5);  // the vertices
    for (BvhLayout layout : kLayouts) {
      SCOPED_TRACE(to_string(layout));
      run_with_threads(2, [&] {
        auto b = built(scene, "bvh", layout);
        std::vector<PointLocation> got(points.size());
        b->locate(points, got);
        for (size_t i = 0; i < points.size(); ++i)
          ASSERT_EQ(int(got[i]), int(expected[i])) << "point " << i << " (" << points[i].x << ", "
                                                   << points[i].y << ", " << points[i].z << ")";
      });
    }
    // Embree (parity of its filter-callback count) agrees away from the
    // vertex planes (the random points).
    run_with_threads(2, [&] {
      auto e = built(scene, "embree");
      std::vector<PointLocation> got(points.size());
      e->locate(points, got);
      for (size_t i = 0; i < points.size(); i += 5) EXPECT_EQ(int(got[i]), int(expected[i])) << i;
    });
  }
}

void expect_same(const ClosestPoint& a, const ClosestPoint& b, size_t i) {
  EXPECT_EQ(a.geom_id, b.geom_id) << i;
  EXPECT_EQ(a.prim_id, b.prim_id) << i;
  EXPECT_EQ(a.distance, b.distance) << i;
  EXPECT_EQ(a.point.x, b.point.x) << i;
  EXPECT_EQ(a.point.y, b.point.y) << i;
  EXPECT_EQ(a.point.z, b.point.z) << i;
  EXPECT_EQ(a.u, b.u) << i;
  EXPECT_EQ(a.v, b.v) << i;
}

TEST(PointQueries, ClosestEqualsBruteForceOnEveryLayoutAndBuilder) {
  const TriangleMesh meshes[] = {generate_torus(3000), test::random_soup(2000, 5, 0.05f),
                                 subdivided_cube(6)};
  for (const TriangleMesh& mesh : meshes) {
    SCOPED_TRACE(mesh.name);
    Scene scene;
    scene.add_mesh(mesh);
    std::vector<Vec3f> points = make_points(scene, PointKind::kHard, 1000, 29);
    points.push_back(Vec3f{0.0f, 0.0f, 0.0f});
    const float inf = std::numeric_limits<float>::infinity();
    std::vector<ClosestPoint> expected, bounded;
    const float reach = 0.05f;
    for (const Vec3f& p : points) {
      expected.push_back(exact_closest(scene, p, inf));
      bounded.push_back(exact_closest(scene, p, reach));
    }
    size_t beyond = 0;
    for (const ClosestPoint& c : bounded) beyond += !c.found();
    EXPECT_GT(beyond, 0u);
    EXPECT_LT(beyond, points.size());
    const BuilderKind builders[] = {BuilderKind::kSweep, BuilderKind::kBinned,
                                    BuilderKind::kParallel, BuilderKind::kMorton};
    for (BvhLayout layout : kLayouts)
      for (BuilderKind builder : builders) {
        SCOPED_TRACE(std::string(to_string(layout)) + "/" + std::string(to_string(builder)));
        run_with_threads(2, [&] {
          auto b = built(scene, "bvh", layout, builder);
          std::vector<ClosestPoint> got(points.size());
          b->closest(points, inf, got);
          for (size_t i = 0; i < points.size(); ++i) expect_same(got[i], expected[i], i);
          b->closest(points, reach, got);
          for (size_t i = 0; i < points.size(); ++i) expect_same(got[i], bounded[i], i);
        });
      }
    run_with_threads(2, [&] {
      auto e = built(scene, "embree");
      std::vector<ClosestPoint> got(points.size());
      e->closest(points, inf, got);
      for (size_t i = 0; i < points.size(); ++i) EXPECT_EQ(got[i].distance, expected[i].distance);
    });
  }
}

// The exact distance of the reported point is the reported distance: a
// query with exactly that maximum finds it (inclusive), one ulp less not
// unless another triangle is as near.
TEST(PointQueries, MaximumDistanceIsInclusive) {
  Scene scene;
  scene.add_mesh(subdivided_cube(2));
  const std::vector<Vec3f> points = {{0.0f, 0.0f, 3.0f}, {0.25f, 0.5f, -1.75f}};
  run_with_threads(2, [&] {
    auto b = built(scene, "bvh");
    std::vector<ClosestPoint> free(points.size()), at(points.size()), below(points.size());
    b->closest(points, std::numeric_limits<float>::infinity(), free);
    for (size_t i = 0; i < points.size(); ++i) {
      ASSERT_TRUE(free[i].found());
      b->closest({&points[i], 1}, free[i].distance, {&at[i], 1});
      b->closest({&points[i], 1}, std::nextafter(free[i].distance, 0.0f), {&below[i], 1});
      expect_same(at[i], free[i], i);
      EXPECT_FALSE(below[i].found()) << i;
    }
    EXPECT_EQ(free[0].distance, 2.0f);
    EXPECT_EQ(free[1].distance, 0.75f);
  });
}

TEST(PointQueries, InvalidPointsAreOutsideWithNothingNear) {
  Scene scene;
  scene.add_mesh(subdivided_cube(2));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Vec3f> points = {{nan, 0, 0}, {0, 1e30f, 0}, {0, 0, -INFINITY}};
  for (const char* backend : {"bvh", "embree"}) {
    SCOPED_TRACE(backend);
    run_with_threads(2, [&] {
      auto b = built(scene, backend);
      std::vector<PointLocation> where(points.size());
      std::vector<ClosestPoint> near(points.size());
      b->locate(points, where);
      b->closest(points, std::numeric_limits<float>::infinity(), near);
      for (size_t i = 0; i < points.size(); ++i) {
        EXPECT_EQ(where[i], PointLocation::kOutside) << i;
        EXPECT_FALSE(near[i].found()) << i;
        EXPECT_EQ(near[i].distance, std::numeric_limits<float>::infinity()) << i;
      }
    });
  }
}

TEST(PointQueries, MollerTestRefusesWithAnOptionError) {
  Scene scene;
  scene.add_mesh(subdivided_cube(2));
  BackendOptions o;
  o.triangle_test = TriangleTestKind::kMoller;
  auto b = make_intersector("bvh", o);
  b->build(scene);
  const std::vector<Vec3f> points = {{0, 0, 0}};
  std::vector<PointLocation> where(1);
  std::vector<ClosestPoint> near(1);
  EXPECT_THROW(b->locate(points, where), OptionError);
  EXPECT_THROW(b->closest(points, 1.0f, near), OptionError);
}

}  // namespace
}  // namespace hprt
