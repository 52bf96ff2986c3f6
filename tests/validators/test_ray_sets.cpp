// The ray-set catalogue: names, counts and determinism of every kind, the
// defining property of each hard kind and, through Embree, the hits each
// promises (probes hit, NaN rays miss). The workload kinds: tests/workload.
#include "validators/ray_sets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "core/error.h"
#include "tests/support/embree_reference.h"
#include "tests/support/ray_set_scene.h"

namespace hprt {
namespace {

using test::closest_hits;
using test::embree_over;
using test::same_bits;

// Closed icosphere-like mesh: an octahedron subdivided `levels` times with its
// vertices pushed onto the sphere (shared vertices, so every edge has two
// triangles).
TriangleMesh sphere_mesh(int levels, float radius, Vec3f centre) {
  TriangleMesh m;
  m.name = "sphere";
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {Vec3u{{0, 2, 4}}, Vec3u{{2, 1, 4}}, Vec3u{{1, 3, 4}}, Vec3u{{3, 0, 4}},
                 Vec3u{{2, 0, 5}}, Vec3u{{1, 2, 5}}, Vec3u{{3, 1, 5}}, Vec3u{{0, 3, 5}}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.positions.push_back(normalize((m.positions[a] + m.positions[b]) * 0.5f));
      return mid[key] = uint32_t(m.positions.size() - 1);
    };
    std::vector<Vec3u> next;
    for (const Vec3u& t : m.triangles) {
      const uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.push_back(Vec3u{{t[0], a, c}});
      next.push_back(Vec3u{{a, t[1], b}});
      next.push_back(Vec3u{{c, b, t[2]}});
      next.push_back(Vec3u{{a, b, c}});
    }
    m.triangles = std::move(next);
  }
  for (Vec3f& p : m.positions) p = p * radius + centre;
  return m;
}

// The closed unit sphere at the origin, 2048 triangles.
Scene sphere_scene() { return test::ray_set_scene(sphere_mesh(4, 1.0f, Vec3f(0.0f))); }

TEST(RaySets, EveryKindGivesNRaysDeterministically) {
  const Scene s = sphere_scene();
  auto b = embree_over(s);
  for (const std::string& name : ray_kind_names()) {
    SCOPED_TRACE(name);
    const RayKind kind = parse_ray_kind(name);
    EXPECT_EQ(to_string(kind), name);
    const std::vector<Ray> a = make_rays(s, kind, 500, 7, b.get());
    EXPECT_EQ(a.size(), 500u);
    EXPECT_TRUE(same_bits(a, make_rays(s, kind, 500, 7, b.get())));
    EXPECT_FALSE(same_bits(a, make_rays(s, kind, 500, 8, b.get())));
    EXPECT_TRUE(make_rays(s, kind, 0, 7, b.get()).empty());
  }
}

TEST(RaySets, UnknownKindIsInputError) {
  try {
    parse_ray_kind("diagonal");
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.key(), "kind");  // the CLI shows it as --kind
    EXPECT_EQ(std::string(e.what()).rfind("kind: unknown ray kind 'diagonal'", 0), 0u);
  }
}

TEST(RaySets, AxisRaysHaveExactSignedZeros) {
  const Scene s = sphere_scene();
  const AABB box = s.bounds();
  size_t neg_zero = 0, pos_zero = 0, on_plane = 0;
  for (const Ray& r : make_rays(s, RayKind::kAxis, 2000, 11)) {
    int ones = 0;
    for (int k = 0; k < 3; ++k) {
      if (r.dir[k] == 1.0f || r.dir[k] == -1.0f) {
        ++ones;
        on_plane += r.org[k] == box.min[k] || r.org[k] == box.max[k];
      } else {
        ASSERT_EQ(r.dir[k], 0.0f);
        (std::signbit(r.dir[k]) ? neg_zero : pos_zero) += 1;
      }
    }
    EXPECT_EQ(ones, 1);
  }
  EXPECT_GT(neg_zero, 500u);
  EXPECT_GT(pos_zero, 500u);
  EXPECT_GT(on_plane, 500u);
}

TEST(RaySets, NanRaysAllMissThroughEmbree) {
  const Scene s = sphere_scene();
  auto b = embree_over(s);
  const std::vector<Ray> rays = make_rays(s, RayKind::kNan, 800, 2);
  for (const Hit& h : closest_hits(*b, rays)) EXPECT_FALSE(h.hit());
  std::vector<uint8_t> occ(rays.size());
  b->occluded(rays, occ);
  for (uint8_t o : occ) EXPECT_EQ(o, 0);
}

TEST(RaySets, ProbesFromInsideAClosedMeshHit) {
  Scene s;
  s.add_mesh(sphere_mesh(3, 2.0f, Vec3f(10.0f, -3.0f, 1.0f)));
  for (RayKind kind : {RayKind::kVertexProbe, RayKind::kEdgeProbe}) {
    SCOPED_TRACE(std::string(to_string(kind)));
    const std::vector<Ray> rays = make_rays(s, kind, 3000, 4);
    for (const Ray& r : rays) EXPECT_NEAR(length(r.org - Vec3f(10.0f, -3.0f, 1.0f)), 0.0f, 1e-4f);
    for (bool robust : {false, true}) {
      auto b = embree_over(s, robust);
      const std::vector<Hit> hits = closest_hits(*b, rays);
      size_t leaks = 0;
      for (const Hit& h : hits) leaks += !h.hit();
      if (robust) {
        EXPECT_EQ(leaks, 0u);
      } else {
        RecordProperty(std::string(to_string(kind)) + "_nonrobust_leaks", int(leaks));
      }
      for (const Hit& h : hits) {
        if (h.hit()) {
          EXPECT_NEAR(h.t, 1.0f, 1e-3f);  // the target sits at t = 1
        }
      }
    }
  }
}

TEST(RaySets, ProbesNeedAClosedMesh) {
  Scene s;
  TriangleMesh m = sphere_mesh(1, 1.0f, Vec3f(0.0f));
  m.triangles.pop_back();  // a hole
  s.add_mesh(m);
  EXPECT_THROW(make_rays(s, RayKind::kVertexProbe, 10, 1), InputError);
  EXPECT_THROW(make_rays(Scene{}, RayKind::kGrazing, 10, 1), InputError);
}

TEST(RaySets, GrazingRaysSkimTheirTriangle) {
  // One triangle in the plane z = 0: the normal component of each ray is
  // its z, and every ray must cross the plane inside the triangle.
  Scene s;
  TriangleMesh m;
  m.name = "flat";
  m.positions = {{0, 0, 0}, {3, 0, 0}, {0, 3, 0}};
  m.triangles = {Vec3u{{0, 1, 2}}};
  s.add_mesh(m);
  auto b = embree_over(s, true);
  const std::vector<Ray> rays = make_rays(s, RayKind::kGrazing, 2000, 6);
  const std::vector<Hit> hits = closest_hits(*b, rays);
  size_t up = 0, down = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    EXPECT_NEAR(length(r.dir), 1.0f, 1e-5f);
    EXPECT_GT(std::fabs(r.dir.z), 0.9e-7f);
    EXPECT_LT(std::fabs(r.dir.z), 1.1e-4f);
    (r.dir.z > 0.0f ? up : down) += 1;
    ASSERT_TRUE(hits[i].hit()) << "grazing ray " << i << " missed its triangle";
    EXPECT_NEAR(hits[i].u, 1.0f / 3.0f, 1e-3f);  // through the centroid
    EXPECT_NEAR(hits[i].v, 1.0f / 3.0f, 1e-3f);
  }
  EXPECT_GT(up, 500u);
  EXPECT_GT(down, 500u);
  // On a sphere most grazing rays hit (some first clip a neighbour).
  const Scene sphere = sphere_scene();
  auto bs = embree_over(sphere, true);
  size_t hit = 0;
  for (const Hit& h : closest_hits(*bs, make_rays(sphere, RayKind::kGrazing, 2000, 6)))
    hit += h.hit();
  EXPECT_GT(hit, 1800u);
}

TEST(RaySets, KindsTheSceneCannotGiveAreInputErrors) {
  Scene s = sphere_scene();
  EXPECT_THROW(make_rays(s, RayKind::kShadow, 10, 1, nullptr), std::invalid_argument);
  s.lights.clear();
  auto b = embree_over(s);
  EXPECT_THROW(make_rays(s, RayKind::kShadow, 10, 1, b.get()), InputError);
  const Scene empty;
  EXPECT_THROW(make_rays(empty, RayKind::kGrazing, 10, 1), InputError);
  EXPECT_THROW(make_rays(empty, RayKind::kAxis, 10, 1), InputError);
}

}  // namespace
}  // namespace hprt
