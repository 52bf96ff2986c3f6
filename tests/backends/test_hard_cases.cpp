// HardCases: numerically hard rays through the bvh backend. Vertex and edge
// probes from inside a closed icosphere (a miss is a leak: 0 allowed for the
// watertight test, Möller-Trumbore only reported), axis-parallel rays with ±0
// components through vertices, the mesh far from the origin and tiny,
// degenerate and NaN triangles, invalid rays, rays starting on a surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>
#include <utility>

#include "backends/intersector.h"
#include "core/parallel.h"
#include "tests/support/bvh_trace_helpers.h"
#include "tests/support/probe_rays.h"

namespace hprt {
namespace {

using test::kInf;

TriangleMesh transformed(TriangleMesh m, float scale, Vec3f offset) {
  for (Vec3f& p : m.positions) p = p * scale + offset;
  return m;
}

// Rays from `centre` aimed exactly at every vertex and every edge midpoint.
std::vector<Ray> probes(const TriangleMesh& m, Vec3f centre) {
  return test::aimed_at_vertices_and_edges(m, [&](Vec3f) { return centre; });
}

// Axis-parallel rays through every vertex from inside the sphere: for each
// axis, origin = the vertex with that coordinate set to the centre's, the
// direction ±1 along the axis and ±0 in the other two components.
std::vector<Ray> axis_probes(const TriangleMesh& m, Vec3f centre) {
  std::vector<Ray> rays;
  for (const Vec3f& p : m.positions)
    for (int axis = 0; axis < 3; ++axis) {
      if (p[axis] == centre[axis]) continue;
      for (int signs = 0; signs < 4; ++signs) {
        Ray r;
        r.org = p;
        r.org[axis] = centre[axis];
        const int o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
        r.dir[axis] = p[axis] > centre[axis] ? 1.0f : -1.0f;
        r.dir[o1] = (signs & 1) ? -0.0f : 0.0f;
        r.dir[o2] = (signs & 2) ? -0.0f : 0.0f;
        rays.push_back(r);
      }
    }
  return rays;
}

// Whether `p` is inside the closed mesh: the parity of the triangles the
// watertight test hits along the whole line through p, the same for three
// directions (the test decides every crossing exactly, so the parity cannot
// depend on the direction). Empty when p lies on the surface or within
// 1e-5 * scale of it, where a crossing's t may round to either side of 0.
std::optional<bool> inside_by_parity(const TriangleMesh& m, Vec3f p, float scale) {
  int parity[3] = {};
  const Vec3f dirs[3] = {{0.31f, -0.72f, 0.6f}, {-0.9f, 0.1f, -0.41f}, {0.05f, 0.66f, -0.73f}};
  for (int k = 0; k < 3; ++k) {
    Ray r;
    r.org = p;
    r.dir = dirs[k];
    const auto prep = WatertightTest::prepare(r);
    for (const Vec3u& t : m.triangles) {
      TriangleHit h;
      if (!WatertightTest::intersect(prep, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]],
                                     -kInf, kInf, h))
        continue;
      if (std::fabs(h.t) <= 1e-5f * scale) return std::nullopt;
      parity[k] ^= h.t > 0.0f;
    }
  }
  EXPECT_EQ(parity[0], parity[1]);
  EXPECT_EQ(parity[0], parity[2]);
  return parity[0] == 1;
}

// Misses of the default (bvh8) layout; every layout must miss the same rays,
// since the layout only changes how the tree is stored.
size_t count_misses(const Scene& scene, const std::vector<Ray>& rays, TriangleTestKind kind) {
  std::vector<size_t> misses_per_layout;
  for (BvhLayout layout : {BvhLayout::kBvh2, BvhLayout::kBvh4, BvhLayout::kBvh8}) {
    BackendOptions o;
    o.triangle_test = kind;
    o.threads = 2;
    o.layout = layout;
    misses_per_layout.push_back(run_with_threads(2, [&] {
      auto isect = make_intersector("bvh", o);
      isect->build(scene);
      std::vector<Hit> hits(rays.size());
      isect->intersect(rays, hits);
      std::vector<uint8_t> occ(rays.size());
      isect->occluded(rays, occ);
      size_t misses = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        misses += !hits[i].hit();
        EXPECT_EQ(occ[i], hits[i].hit() ? 1 : 0);
      }
      return misses;
    }));
  }
  EXPECT_EQ(misses_per_layout[0], misses_per_layout[2]) << "bvh2 vs bvh8";
  EXPECT_EQ(misses_per_layout[1], misses_per_layout[2]) << "bvh4 vs bvh8";
  return misses_per_layout[2];
}

void expect_no_leaks(float scale, Vec3f offset, const char* label) {
  Scene scene;
  const TriangleMesh sphere = transformed(test::icosphere(4), scale, offset);
  const auto rays = probes(sphere, offset);
  // An axis-parallel ray through a vertex whose origin (the point of its line
  // nearest the centre) is outside the mesh only touches it at a silhouette
  // vertex: by the fill rule it may hit two triangles or none; one from a
  // point of the surface may leave without a crossing. Only rays from inside
  // must hit.
  // The sphere is a convex polytope: a point nearer the centre than every
  // face plane is inside, one farther than every vertex outside; the few in
  // between are decided by parity.
  double inner = kInf, outer = 0.0;
  for (const Vec3u& t : sphere.triangles) {
    const Vec3d a(sphere.positions[t[0]] - offset), b(sphere.positions[t[1]] - offset),
        c(sphere.positions[t[2]] - offset);
    const Vec3d n = normalize(cross(b - a, c - a));
    inner = std::min(inner, std::fabs(dot(n, a)));
    outer = std::max(outer, length(a));
  }
  std::vector<Ray> axis_rays;
  size_t touching = 0;
  for (const Ray& r : axis_probes(sphere, offset)) {
    const double d = length(Vec3d(r.org - offset));
    const bool inside = d < inner * (1 - 1e-4) ? true
                        : d > outer * (1 + 1e-4)
                            ? false
                            : inside_by_parity(sphere, r.org, scale).value_or(false);
    if (inside)
      axis_rays.push_back(r);
    else
      ++touching;
  }
  scene.add_mesh(sphere);
  const size_t wt = count_misses(scene, rays, TriangleTestKind::kWatertight);
  const size_t mt = count_misses(scene, rays, TriangleTestKind::kMoller);
  const size_t wt_axis = count_misses(scene, axis_rays, TriangleTestKind::kWatertight);
  const size_t mt_axis = count_misses(scene, axis_rays, TriangleTestKind::kMoller);
  EXPECT_EQ(wt, 0u) << label;
  EXPECT_EQ(wt_axis, 0u) << label;
  std::printf(
      "[ info ] %s: %zu vertex/edge probes, leaks watertight %zu, MT %zu; "
      "%zu axis-parallel probes from inside, leaks watertight %zu, MT %zu (%zu more only "
      "touch a silhouette vertex)\n",
      label, rays.size(), wt, mt, axis_rays.size(), wt_axis, mt_axis, touching);
}

TEST(HardCases, VertexAndEdgeProbesFromInsideDoNotLeak) {
  expect_no_leaks(1.0f, {0, 0, 0}, "unit sphere");
}

TEST(HardCases, ProbesFarFromTheOrigin) {
  // At 1e6 the float spacing is 1/16, so the radius is 10 to keep every
  // triangle non-degenerate after rounding (the mesh stays closed).
  expect_no_leaks(10.0f, {1e6f, -1e6f, 1e6f}, "offset 1e6, radius 10");
}

TEST(HardCases, ProbesOnATinyMesh) { expect_no_leaks(1e-6f, {0, 0, 0}, "scale 1e-6"); }

TEST(HardCases, DegenerateTrianglesNeverHitNorDisturb) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const TriangleMesh clean = test::grid(20, 20);
  TriangleMesh dirty = clean;
  // Degenerates on top of the grid (z = 0.5, above it): zero area, repeated
  // vertices, collinear, NaN and inf coordinates.
  test::add_triangle(dirty, {0.2f, 0.2f, 0.5f}, {0.2f, 0.2f, 0.5f}, {0.8f, 0.8f, 0.5f});
  test::add_triangle(dirty, {0.0f, 0.0f, 0.5f}, {0.5f, 0.5f, 0.5f}, {1.0f, 1.0f, 0.5f});
  test::add_triangle(dirty, {0.0f, 0.0f, 0.5f}, {nan, 0.0f, 0.5f}, {0.0f, 1.0f, 0.5f});
  test::add_triangle(dirty, {0.0f, 0.0f, 0.5f}, {1.0f, kInf, 0.5f}, {0.0f, 1.0f, 0.5f});
  test::add_triangle(dirty, {0.3f, 0.3f, 0.5f}, {0.3f, 0.3f, 0.5f}, {0.3f, 0.3f, 0.5f});
  Scene a, b;
  a.add_mesh(clean);
  b.add_mesh(dirty);
  std::vector<Ray> rays = test::coherent_rays(AABB{{0, 0, 0}, {1, 1, 0.1f}}, 50, 50);
  for (int i = 0; i < 200; ++i) {  // straight down along the degenerate segments
    Ray r;
    const float s = (i + 0.5f) / 200.0f;
    r.org = {0.1f + 0.8f * s, 0.1f + 0.8f * s, 2.0f};
    r.dir = {0.0f, -0.0f, -1.0f};
    rays.push_back(r);
  }
  for (TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller}) {
    BackendOptions o;
    o.triangle_test = kind;
    auto ia = make_intersector("bvh", o);
    auto ib = make_intersector("bvh", o);
    ia->build(a);
    ib->build(b);
    EXPECT_EQ(ib->info().stats.invalid_triangles, 5u);
    std::vector<Hit> ha(rays.size()), hb(rays.size());
    ia->intersect(rays, ha);
    ib->intersect(rays, hb);
    for (size_t i = 0; i < rays.size(); ++i) {
      EXPECT_EQ(ha[i].t, hb[i].t) << i;
      EXPECT_EQ(ha[i].prim_id, hb[i].prim_id) << i;
      EXPECT_LT(hb[i].prim_id == kInvalidId ? 0u : hb[i].prim_id, clean.triangle_count());
    }
  }
}

TEST(HardCases, InvalidRaysMiss) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Scene scene;
  scene.add_mesh(test::icosphere(2));
  std::vector<Ray> rays;
  auto add = [&](Vec3f o, Vec3f d, float tnear, float tfar) {
    Ray r;
    r.org = o;
    r.dir = d;
    r.tnear = tnear;
    r.tfar = tfar;
    rays.push_back(r);
  };
  add({0, 0, 0}, {nan, 1, 0}, 0, kInf);
  add({0, 0, 0}, {0, nan, 0}, 0, kInf);
  add({nan, 0, 0}, {0, 1, 0}, 0, kInf);
  add({0, 0, 0}, {kInf, 1, 0}, 0, kInf);
  add({0, 0, 0}, {0, -kInf, 0}, 0, kInf);
  add({kInf, 0, 0}, {-1, 0, 0}, 0, kInf);
  add({0, 0, 0}, {0, 0, 0}, 0, kInf);
  add({0, 0, 0}, {-0.0f, 0, -0.0f}, 0, kInf);
  add({0, 0, 0}, {0, 1, 0}, 2.0f, 1.0f);  // tnear > tfar
  add({0, 0, 0}, {0, 1, 0}, nan, kInf);
  add({0, 0, 0}, {0, 1, 0}, 0, nan);
  for (TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller})
    EXPECT_EQ(count_misses(scene, rays, kind), rays.size());
}

// Embree 3 accepts a hit only for tnear < t <= tfar (triangle_intersector_
// moeller.h / _woop.h), so a ray starting exactly on a surface with tnear = 0
// does not report that surface at t = 0 but does report a rounding hit at a
// tiny positive t. The bvh backend does the same; the answers are compared
// with the Embree backend's.
TEST(HardCases, RaysStartingOnASurface) {
  Scene scene;
  TriangleMesh m;
  test::add_triangle(m, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});              // z = 0 plane
  test::add_triangle(m, {0, 0, 1}, {1, 0, 1}, {0, 1, 1});              // z = 1 plane
  test::add_triangle(m, {5, 0, 0}, {6, 0.3f, 0.7f}, {5.2f, 1, 0.1f});  // oblique
  scene.add_mesh(m);
  std::vector<Ray> rays;
  auto add = [&](Vec3f o, Vec3f d, float tnear) {
    Ray r;
    r.org = o;
    r.dir = d;
    r.tnear = tnear;
    rays.push_back(r);
  };
  add({0.25f, 0.25f, 0.0f}, {0.1f, 0.2f, 1.0f}, 0.0f);   // exactly on z = 0, going up
  add({0.25f, 0.25f, 0.0f}, {0.1f, 0.2f, -1.0f}, 0.0f);  // exactly on z = 0, going down
  add({0.25f, 0.25f, 1.0f}, {0.0f, 0.0f, 1.0f}, 0.0f);   // on z = 1, leaving
  const Vec3f p = Vec3f{5, 0, 0} * 0.2f + Vec3f{6, 0.3f, 0.7f} * 0.5f + Vec3f{5.2f, 1, 0.1f} * 0.3f;
  add(p, {0.3f, -0.2f, 0.9f}, 0.0f);  // on the oblique one (up to rounding)
  BackendOptions o;
  std::vector<Hit> hb(rays.size()), he(rays.size());
  auto bvh = make_intersector("bvh", o);
  auto emb = make_intersector("embree", o);
  bvh->build(scene);
  emb->build(scene);
  bvh->intersect(rays, hb);
  emb->intersect(rays, he);  // (Embree asserts tnear >= 0, so no negative tnear here)
  // A negative tnear is outside Embree's contract; hprt defines it as a miss
  // on both backends (core/ray.h ray_valid).
  {
    Ray r = rays[0];
    r.tnear = -1.0f;
    ASSERT_TRUE(bvh->info().has_tree_stats);
    std::vector<Hit> one(1), two(1);
    bvh->intersect(std::span<const Ray>(&r, 1), one);
    emb->intersect(std::span<const Ray>(&r, 1), two);
    EXPECT_FALSE(one[0].hit());
    EXPECT_FALSE(two[0].hit());
  }
  // Exactly on z = 0 going up: the z = 0 triangle is at t = 0 (excluded),
  // so the hit is the z = 1 one at t = 1.
  ASSERT_TRUE(hb[0].hit());
  EXPECT_EQ(hb[0].prim_id, 1u);
  EXPECT_FLOAT_EQ(hb[0].t, 1.0f);
  EXPECT_FALSE(hb[1].hit());
  EXPECT_FALSE(hb[2].hit());
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(hb[i].hit(), he[i].hit()) << i;
    if (hb[i].hit() && he[i].hit()) {
      EXPECT_EQ(hb[i].prim_id, he[i].prim_id) << i;
      EXPECT_NEAR(hb[i].t, he[i].t, 1e-5f * std::max(1.0f, std::fabs(he[i].t))) << i;
    }
  }
}

}  // namespace
}  // namespace hprt
