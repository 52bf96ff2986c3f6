// Procedural meshes: count rules, determinism, closedness and orientation of
// sphere/torus (and after subdivision), no degenerate or non-finite triangles.
#include "meshgen/mesh_generators.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

#include "core/error.h"
#include "core/parallel.h"
#include "io/mesh/generate_mesh.h"

namespace hprt {

namespace {

// Every directed edge appears exactly once and its reverse exactly once:
// closed (two triangles per undirected edge) and consistently oriented.
::testing::AssertionResult closed_and_oriented(const TriangleMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const Vec3u& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, n] : directed) {
    if (n != 1) return ::testing::AssertionFailure() << "directed edge used " << n << " times";
    const auto rev = directed.find({e.second, e.first});
    if (rev == directed.end() || rev->second != 1)
      return ::testing::AssertionFailure() << "edge " << e.first << "-" << e.second << " is open";
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult all_valid(const TriangleMesh& m) {
  for (const Vec3f& p : m.positions)
    if (!is_finite(p)) return ::testing::AssertionFailure() << "non-finite vertex";
  for (size_t i = 0; i < m.triangle_count(); ++i)
    if (!m.triangle_valid(i)) return ::testing::AssertionFailure() << "degenerate triangle " << i;
  return ::testing::AssertionSuccess();
}

// Sum of the signed volumes of the triangles' tetrahedra with the origin: > 0
// when the closed surface's normals point outwards.
double signed_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (const Vec3u& t : m.triangles)
    v += dot(Vec3d(m.positions[t[0]]), cross(Vec3d(m.positions[t[1]]), Vec3d(m.positions[t[2]]))) /
         6.0;
  return v;
}

constexpr size_t kGeneratorBlockForTest = 16384;  // kGeneratorBlock in meshgen/generate_random.h

bool same_mesh(const TriangleMesh& a, const TriangleMesh& b) {
  return a.positions == b.positions && a.triangles == b.triangles;
}

}  // namespace

TEST(MeshGenerators, SphereCountRule) {
  EXPECT_EQ(sphere_segments(1), 1);
  EXPECT_EQ(sphere_segments(20), 1);
  EXPECT_EQ(sphere_segments(21), 2);
  EXPECT_EQ(sphere_segments(1000), 8);
  EXPECT_EQ(sphere_segments(1000000), 224);
  const TriangleMesh m = generate_sphere(1000);
  EXPECT_EQ(m.triangle_count(), 1280u);
  EXPECT_EQ(m.vertex_count(), 10u * 64 + 2);
  EXPECT_EQ(generate_sphere(20).triangle_count(), 20u);
  EXPECT_EQ(generate_sphere(20 * 49).triangle_count(), 20u * 49);  // exact square hit
}

TEST(MeshGenerators, SphereClosedOnUnitSphereOutward) {
  for (size_t n : {20u, 80u, 500u, 3000u}) {
    const TriangleMesh m = generate_sphere(n);
    EXPECT_TRUE(closed_and_oriented(m)) << n;
    EXPECT_TRUE(all_valid(m)) << n;
    for (const Vec3f& p : m.positions) ASSERT_NEAR(length(p), 1.0f, 1e-6f);
    EXPECT_GT(signed_volume(m), 0.0);
    // Each triangle's normal points away from the centre.
    for (const Vec3u& t : m.triangles) {
      const Vec3f a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
      ASSERT_GT(dot(cross(b - a, c - a), a + b + c), 0.0f);
    }
  }
  // Fine spheres approach the true volume 4/3 π.
  EXPECT_NEAR(signed_volume(generate_sphere(20000)), 4.0 / 3.0 * M_PI, 0.01);
}

TEST(MeshGenerators, BumpySphereClosedOutwardAndBumpy) {
  for (size_t n : {80u, 3000u, 20000u}) {
    const TriangleMesh m = generate_bumpy_sphere(n, 5);
    const TriangleMesh s = generate_sphere(n);
    EXPECT_EQ(m.triangles, s.triangles) << n;  // the sphere's connectivity
    EXPECT_TRUE(closed_and_oriented(m)) << n;
    EXPECT_TRUE(all_valid(m)) << n;
    EXPECT_GT(signed_volume(m), 0.0);
    float lo = 2.0f, hi = 0.0f;
    for (size_t i = 0; i < m.positions.size(); ++i) {
      const float r = length(m.positions[i]);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
      // Moved along its own direction only.
      ASSERT_LT(length(m.positions[i] / r - s.positions[i]), 1e-5f);
    }
    EXPECT_GE(lo, 0.8f);
    EXPECT_LE(hi, 1.2f);
    if (n >= 3000) {
      EXPECT_GT(hi - lo, 0.1f) << "not bumpy";
    }
  }
  EXPECT_TRUE(same_mesh(generate_bumpy_sphere(1000, 3), generate_bumpy_sphere(1000, 3)));
  EXPECT_FALSE(same_mesh(generate_bumpy_sphere(1000, 3), generate_bumpy_sphere(1000, 4)));
  EXPECT_TRUE(same_mesh(run_with_threads(1, [] { return generate_bumpy_sphere(50000, 9); }),
                        run_with_threads(2, [] { return generate_bumpy_sphere(50000, 9); })));
}

TEST(MeshGenerators, TorusCountClosedOutward) {
  for (size_t n : {1u, 18u, 1000u, 20000u}) {
    const TriangleMesh m = generate_torus(n);
    EXPECT_GE(m.triangle_count(), n);
    const size_t minor = std::max<size_t>(3, size_t(std::llround(std::sqrt(n / 6.0))));
    EXPECT_LT(m.triangle_count(), std::max<size_t>(n, 18) + 2 * minor) << n;
    EXPECT_EQ(m.vertex_count() * 2, m.triangle_count());  // genus 1: V = T / 2
    EXPECT_TRUE(closed_and_oriented(m)) << n;
    EXPECT_TRUE(all_valid(m)) << n;
    EXPECT_GT(signed_volume(m), 0.0);
  }
  EXPECT_EQ(generate_torus(1000).triangle_count(), 1014u);
}

TEST(MeshGenerators, SoupAndSliversExactCountInUnitCube) {
  for (const TriangleMesh& m : {generate_soup(5000, 7), generate_slivers(5000, 7)}) {
    EXPECT_EQ(m.triangle_count(), 5000u);
    EXPECT_TRUE(all_valid(m));
    const AABB b = m.bounds();
    EXPECT_TRUE(AABB(Vec3f(0.0f), Vec3f(1.0f)).contains(b));
    EXPECT_GT(b.diagonal().x, 0.9f);  // spread over the cube
  }
}

TEST(MeshGenerators, SliversAreThin) {
  const TriangleMesh m = generate_slivers(200, 3);
  for (const Vec3u& t : m.triangles) {
    const Vec3f a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    const float len = length(b - a);
    const float height = length(cross(b - a, c - a)) / len;
    EXPECT_GE(len, 0.05f * 0.999f);
    EXPECT_LE(len, 0.3f * 1.001f);
    EXPECT_NEAR(len / height, 1000.0f, 5.0f);
  }
}

TEST(MeshGenerators, RandomKindsDeterministicPerSeed) {
  EXPECT_TRUE(same_mesh(generate_soup(1000, 42), generate_soup(1000, 42)));
  EXPECT_FALSE(same_mesh(generate_soup(1000, 42), generate_soup(1000, 43)));
  EXPECT_TRUE(same_mesh(generate_slivers(1000, 42), generate_slivers(1000, 42)));
  EXPECT_FALSE(same_mesh(generate_slivers(1000, 42), generate_slivers(1000, 43)));
  EXPECT_TRUE(same_mesh(generate_terrain(1000, 42), generate_terrain(1000, 42)));
  EXPECT_FALSE(same_mesh(generate_terrain(1000, 42), generate_terrain(1000, 43)));
  EXPECT_TRUE(same_mesh(generate_sphere(1000), generate_sphere(1000)));
  EXPECT_TRUE(same_mesh(generate_torus(1000), generate_torus(1000)));
}

TEST(MeshGenerators, RandomKindsIndependentOfThreadCount) {
  const size_t n = 3 * kGeneratorBlockForTest + 17;  // several random streams
  for (int threads : {2, 7}) {
    EXPECT_TRUE(same_mesh(run_with_threads(1, [&] { return generate_soup(n, 9); }),
                          run_with_threads(threads, [&] { return generate_soup(n, 9); })));
    EXPECT_TRUE(same_mesh(run_with_threads(1, [&] { return generate_slivers(n, 9); }),
                          run_with_threads(threads, [&] { return generate_slivers(n, 9); })));
    EXPECT_TRUE(same_mesh(run_with_threads(1, [&] { return generate_terrain(n, 9); }),
                          run_with_threads(threads, [&] { return generate_terrain(n, 9); })));
  }
}

TEST(MeshGenerators, SliverSheetIsAHeightFieldOfHundredToOneSlivers) {
  for (size_t n : {1u, 200u, 5000u, 100000u}) {
    const TriangleMesh m = generate_sliver_sheet(n, 3);
    EXPECT_GE(m.triangle_count(), n);
    const size_t gx =
        size_t(std::lround(std::sqrt(double(m.triangle_count()) / (2.0 * kSliverAspect))));
    ASSERT_EQ(m.triangle_count(), 2 * gx * gx * kSliverAspect) << n;
    EXPECT_LT(2 * (gx - 1) * (gx - 1) * kSliverAspect, n) << "not the smallest grid";
    EXPECT_TRUE(all_valid(m)) << n;
    for (const Vec3u& t : m.triangles) {
      const Vec3f a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
      ASSERT_GT(cross(b - a, c - a).y, 0.0f);  // faces +y
      // Projected onto xz, a right triangle with legs 2/gx and 2/(100 gx).
      const float dx = std::max({a.x, b.x, c.x}) - std::min({a.x, b.x, c.x});
      const float dz = std::max({a.z, b.z, c.z}) - std::min({a.z, b.z, c.z});
      ASSERT_NEAR(dx / dz, float(kSliverAspect), 0.01f * kSliverAspect);
    }
  }
  EXPECT_TRUE(same_mesh(generate_sliver_sheet(5000, 3), generate_sliver_sheet(5000, 3)));
  EXPECT_FALSE(same_mesh(generate_sliver_sheet(5000, 3), generate_sliver_sheet(5000, 4)));
}

TEST(MeshGenerators, TerrainAndPlaneGrid) {
  EXPECT_EQ(grid_segments(1), 1);
  EXPECT_EQ(grid_segments(2), 1);
  EXPECT_EQ(grid_segments(3), 2);
  EXPECT_EQ(grid_segments(20000), 100);
  for (const TriangleMesh& m : {generate_terrain(20000, 5), generate_plane(20000)}) {
    EXPECT_EQ(m.triangle_count(), 20000u);
    EXPECT_EQ(m.vertex_count(), 101u * 101u);
    EXPECT_TRUE(all_valid(m));
    const AABB b = m.bounds();
    EXPECT_FLOAT_EQ(b.min.x, -1.0f);
    EXPECT_FLOAT_EQ(b.max.z, 1.0f);
    for (const Vec3u& t : m.triangles) {  // normals face +y
      const Vec3f a = m.positions[t[0]], p = m.positions[t[1]], c = m.positions[t[2]];
      ASSERT_GT(cross(p - a, c - a).y, 0.0f);
    }
  }
  const AABB tb = generate_terrain(20000, 5).bounds();
  EXPECT_GT(tb.max.y - tb.min.y, 0.05f);  // not flat
  EXPECT_LT(tb.max.y, 0.3f);
  EXPECT_GT(tb.min.y, -0.3f);
  EXPECT_EQ(generate_plane(20000).bounds().max.y, 0.0f);
  EXPECT_EQ(generate_terrain(1000, 1).triangle_count(), 2u * 23 * 23);
}

TEST(MeshGenerators, SubdivideKeepsClosedAndReachesTarget) {
  const TriangleMesh sphere = generate_sphere(20);
  const TriangleMesh m = subdivide_mesh(sphere, 1000);
  EXPECT_EQ(m.triangle_count(), 1280u);  // 20 -> 80 -> 320 -> 1280
  EXPECT_EQ(m.vertex_count(), 642u);     // shared midpoints: V = T/2 + 2
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_TRUE(all_valid(m));
  EXPECT_GT(signed_volume(m), 0.0);
  // Already enough: unchanged.
  EXPECT_TRUE(same_mesh(subdivide_mesh(sphere, 20), sphere));
  // Torus (genus 1) too.
  const TriangleMesh t = subdivide_mesh(generate_torus(18), 100);
  EXPECT_EQ(t.triangle_count(), 18u * 16);
  EXPECT_TRUE(closed_and_oriented(t));
  // An open mesh keeps its boundary: a 2-triangle plane -> 8 triangles, 9 vertices.
  const TriangleMesh p = subdivide_mesh(generate_plane(2), 5);
  EXPECT_EQ(p.triangle_count(), 8u);
  EXPECT_EQ(p.vertex_count(), 9u);
}

TEST(MeshGenerators, SubdivideRejectsBadInput) {
  TriangleMesh empty;
  empty.name = "empty.ply";
  EXPECT_THROW(subdivide_mesh(empty, 10), InputError);
  TriangleMesh bad = generate_sphere(20);
  bad.triangles[3][1] = 999;
  EXPECT_THROW(subdivide_mesh(bad, 100), InputError);
}

TEST(MeshGenerators, GenerateMeshChecksOptions) {
  GenerateSpec spec;
  spec.kind = "sphere";
  spec.tris = 1000;
  EXPECT_EQ(generate_mesh(spec).triangle_count(), 1280u);
  spec.tris = 0;
  try {
    generate_mesh(spec);
    FAIL() << "tris 0 accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.key(), "tris");  // the CLI shows it as --tris
  }
  spec.tris = kMaxGenerateTriangles + 1;
  try {
    generate_mesh(spec);
    FAIL() << "too many accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too many triangles"), std::string::npos);
  }
  spec.tris = 100;
  spec.kind = "cube";
  EXPECT_THROW(generate_mesh(spec), InputError);
  spec.kind = "subdivide";
  EXPECT_THROW(generate_mesh(spec), InputError);  // no --from
  for (const std::string& kind : generator_kinds()) {
    if (kind == "subdivide") continue;
    spec.kind = kind;
    EXPECT_GE(generate_mesh(spec).triangle_count(), 100u) << kind;
  }
}

}  // namespace hprt
