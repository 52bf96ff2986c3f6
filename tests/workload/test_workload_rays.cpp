// The renderer's ray workloads: where each kind starts and goes, that the
// same stream state gives the same rays, and the errors of scenes that cannot
// give a kind. Hits are checked through Embree.
#include "workload/workload_rays.h"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <stdexcept>

#include "core/error.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/embree_reference.h"
#include "tests/support/ray_set_scene.h"
#include "workload/sampling.h"
#include "workload/surface_hits.h"

namespace hprt {
namespace {

using test::closest_hits;
using test::embree_over;
using test::same_bits;

// The unit sphere at the origin, 2000 triangles.
Scene sphere_scene() { return test::ray_set_scene(generate_sphere(2000)); }

TEST(WorkloadRays, SameStreamSameRaysEveryKind) {
  const Scene s = sphere_scene();
  auto b = embree_over(s);
  using Make = std::vector<Ray> (*)(const Scene&, size_t, SplitMix64&, const Intersector*);
  const Make kinds[] = {[](const Scene& sc, size_t n, SplitMix64& r, const Intersector*) {
                          return primary_rays(sc, n, r);
                        },
                        shadow_rays, reflection_rays, diffuse_rays,
                        [](const Scene& sc, size_t n, SplitMix64& r, const Intersector*) {
                          return random_rays(sc, n, r);
                        }};
  for (const Make make : kinds) {
    SplitMix64 a(11), same(11), other(12);
    const std::vector<Ray> rays = make(s, 300, a, b.get());
    EXPECT_EQ(rays.size(), 300u);
    EXPECT_TRUE(same_bits(rays, make(s, 300, same, b.get())));
    EXPECT_FALSE(same_bits(rays, make(s, 300, other, b.get())));
  }
}

TEST(WorkloadRays, PrimaryRaysStartAtTheCameraAndMostlyHit) {
  const Scene s = sphere_scene();
  SplitMix64 rng(1);
  const std::vector<Ray> rays = primary_rays(s, 2000, rng);
  for (const Ray& r : rays) {
    EXPECT_EQ(r.org, s.camera.position);
    EXPECT_NEAR(length(r.dir), 1.0f, 1e-5f);
    EXPECT_LT(r.dir.z, 0.0f);
  }
  auto b = embree_over(s);
  size_t hits = 0;
  for (const Hit& h : closest_hits(*b, rays)) hits += h.hit();
  EXPECT_GT(hits, 200u);   // the sphere fills part of the view ...
  EXPECT_LT(hits, 1900u);  // ... not all of it
}

TEST(WorkloadRays, RandomRaysStartInTheEnlargedBox) {
  const Scene s = sphere_scene();
  const AABB box = s.bounds();
  const AABB big(box.center() - box.diagonal() * 0.5501f, box.center() + box.diagonal() * 0.5501f);
  size_t outside_original = 0;
  SplitMix64 rng(3);
  for (const Ray& r : random_rays(s, 5000, rng)) {
    EXPECT_TRUE(big.contains(r.org));
    outside_original += !box.contains(r.org);
    EXPECT_NEAR(length(r.dir), 1.0f, 1e-5f);
  }
  EXPECT_GT(outside_original, 0u);
}

TEST(WorkloadRays, EmptySceneSpreadsRandomRaysOverTheUnitBox) {
  const Scene empty;
  EXPECT_EQ(scene_box_or_unit(empty).min, Vec3f(-1.0f));
  EXPECT_EQ(scene_box_or_unit(empty).max, Vec3f(1.0f));
  SplitMix64 rng(4);
  for (const Ray& r : random_rays(empty, 100, rng)) EXPECT_LE(std::abs(r.org.x), 1.1f);
}

TEST(WorkloadRays, SurfaceHitsLieOnTheSphereFacingTheCamera) {
  const Scene s = sphere_scene();
  auto b = embree_over(s);
  SplitMix64 rng(2);
  for (const SurfaceHit& h : primary_surface_hits(s, 500, rng, b.get(), "test")) {
    EXPECT_NEAR(length(h.p), 1.0f, 0.01f);
    EXPECT_NEAR(length(h.n), 1.0f, 1e-5f);
    EXPECT_LT(dot(h.n, h.dir), 0.0f);  // the normal faces the incoming ray
  }
}

TEST(WorkloadRays, ShadowRaysEndJustBeforeThePointLight) {
  const Scene s = sphere_scene();
  auto b = embree_over(s);
  SplitMix64 rng(5);
  const std::vector<Ray> rays = shadow_rays(s, 1000, rng, b.get());
  std::vector<uint8_t> occluded(rays.size());
  b->occluded(rays, occluded);
  size_t lit_checked = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    EXPECT_NEAR(length(r.org), 1.0f, 0.01f);  // on the sphere
    const Vec3f to_light = r.org + r.dir;
    EXPECT_NEAR(to_light.x, 3.0f, 1e-5f);
    EXPECT_NEAR(to_light.y, 4.0f, 1e-5f);
    EXPECT_NEAR(to_light.z, 5.0f, 1e-5f);
    EXPECT_LT(r.tfar, 1.0f);
    // Facing the light clearly: the offset origin must not see its own
    // surface (self-intersection) and nothing else is in the way.
    const float facing = dot(normalize(r.org), normalize(r.dir));
    if (facing > 0.2f) {
      ++lit_checked;
      EXPECT_EQ(occluded[i], 0) << "self-occlusion at ray " << i;
    }
    if (facing < -0.2f) {
      EXPECT_EQ(occluded[i], 1) << "back side not shadowed, ray " << i;
    }
  }
  EXPECT_GT(lit_checked, 100u);
}

TEST(WorkloadRays, ReflectionRaysLeaveAConvexSphere) {
  const Scene s = sphere_scene();
  auto b = embree_over(s);
  SplitMix64 rng(9);
  const std::vector<Ray> rays = reflection_rays(s, 1000, rng, b.get());
  const std::vector<Hit> hits = closest_hits(*b, rays);
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_NEAR(length(rays[i].dir), 1.0f, 1e-5f);
    EXPECT_GT(dot(rays[i].dir, normalize(rays[i].org)), -0.1f);  // outward-ish
    EXPECT_FALSE(hits[i].hit()) << "reflection ray " << i << " hit the convex sphere";
  }
}

TEST(WorkloadRays, CosineHemisphereHasTheCosineMean) {
  // E[cos] = 2/3 and E[cos^2] = 1/2 under the cosine-weighted density.
  for (const Vec3f n : {Vec3f(0, 0, 1), Vec3f(0, 0, -1), normalize(Vec3f(1, -2, 0.5f)),
                        normalize(Vec3f(-0.3f, 0.1f, -1e-4f))}) {
    SplitMix64 rng(17);
    double sum = 0.0, sum2 = 0.0;
    const int kSamples = 200000;
    for (int i = 0; i < kSamples; ++i) {
      const Vec3f d = cosine_hemisphere(n, rng);
      ASSERT_NEAR(length(d), 1.0f, 1e-5f);
      const double c = dot(d, n);
      ASSERT_GE(c, -1e-6);
      sum += c;
      sum2 += c * c;
    }
    EXPECT_NEAR(sum / kSamples, 2.0 / 3.0, 0.005) << n.x << " " << n.y << " " << n.z;
    EXPECT_NEAR(sum2 / kSamples, 0.5, 0.005);
  }
}

TEST(WorkloadRays, DiffuseRaysLeaveAConvexSphereOnTheCameraSide) {
  const Scene s = sphere_scene();
  auto b = embree_over(s);
  SplitMix64 rng(21);
  const std::vector<Ray> rays = diffuse_rays(s, 2000, rng, b.get());
  const std::vector<Hit> hits = closest_hits(*b, rays);
  double mean_cos = 0.0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Vec3f n = normalize(rays[i].org);  // outward normal of the unit sphere
    EXPECT_NEAR(length(rays[i].dir), 1.0f, 1e-5f);
    // n is the radial normal, within ~0.06 rad of the facet's.
    EXPECT_GE(dot(s.camera.position - rays[i].org, n), -0.1f);  // a point the camera sees
    EXPECT_GE(dot(rays[i].dir, n), -0.1f);                      // the hemisphere outside the sphere
    EXPECT_FALSE(hits[i].hit()) << "diffuse ray " << i << " hit the convex sphere";
    mean_cos += dot(rays[i].dir, n);
  }
  EXPECT_NEAR(mean_cos / double(rays.size()), 2.0 / 3.0, 0.03);
}

TEST(WorkloadRays, SecondaryRaysNeedABackendALightAndAVisibleScene) {
  Scene s = sphere_scene();
  SplitMix64 rng(1);
  EXPECT_THROW(shadow_rays(s, 10, rng, nullptr), std::invalid_argument);
  s.lights.clear();
  auto b = embree_over(s);
  try {
    shadow_rays(s, 10, rng, b.get());
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.key(), "kind");
    EXPECT_NE(std::string(e.what()).find("need a light"), std::string::npos) << e.what();
  }
  s.camera.look_at = {0.0f, 0.0f, 10.0f};  // looking away: no primary hits
  s.lights.push_back(Light{});
  try {
    reflection_rays(s, 10, rng, b.get());
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("reflection: only 0 of 10 primary rays hit"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hprt
