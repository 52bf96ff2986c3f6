// The five deformers as pure functions of (rest pose, spec, t): identity at
// t = 0 where the formula says so, each one's geometric property (twist keeps
// radii, bend rolls the centre line onto an arc, wave travels, pulse keeps the
// centroid, explode moves triangles rigidly along their own normals), in-place
// use, the same bits for any thread count; and unwelding.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "anim/deformers.h"
#include "core/error.h"
#include "core/parallel.h"
#include "meshgen/mesh_generators.h"

namespace hprt {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// A vertical column of points: a thin cylinder-ish cloud along y.
std::vector<Vec3f> column(int n = 40000) {
  std::vector<Vec3f> p;
  for (int i = 0; i < n; ++i) {
    const float a = float(i) * 0.37f;
    p.push_back({0.2f * std::cos(a) + 1.0f, 2.0f * float(i) / float(n - 1), 0.2f * std::sin(a)});
  }
  return p;
}

std::vector<Vec3f> run(const DeformerSpec& spec, const std::vector<Vec3f>& rest, float t,
                       int threads = 2) {
  std::vector<Vec3f> out(rest.size());
  const RestPose pose = measure_rest_pose(rest);
  run_with_threads(threads, [&] { apply_deformer(spec, pose, t, rest, out); });
  return out;
}

DeformerSpec spec_of(const std::string& kind) {
  DeformerSpec s;
  s.kind = kind;
  return s;
}

TEST(Deformers, IdentityAtTimeZero) {
  const std::vector<Vec3f> rest = column();
  for (const char* kind : {"twist", "bend", "pulse"})
    EXPECT_EQ(run(spec_of(kind), rest, 0.0f), rest) << kind;
  TriangleMesh sphere = generate_sphere(2000);
  unweld(sphere);
  EXPECT_EQ(run(spec_of("explode"), sphere.positions.to_vector(), 0.0f),
            sphere.positions.to_vector());
}

TEST(Deformers, SameBitsForAnyThreadCountAndInPlace) {
  TriangleMesh sphere = generate_sphere(20000);
  unweld(sphere);
  for (const char* kind : {"twist", "bend", "wave", "pulse", "explode"}) {
    const std::vector<Vec3f> one = run(spec_of(kind), sphere.positions.to_vector(), 0.7f, 1);
    EXPECT_EQ(one, run(spec_of(kind), sphere.positions.to_vector(), 0.7f, 3)) << kind;
    std::vector<Vec3f> in_place = sphere.positions.to_vector();
    const RestPose pose = measure_rest_pose(sphere.positions.to_vector());
    apply_deformer(spec_of(kind), pose, 0.7f, in_place, in_place);
    EXPECT_EQ(one, in_place) << kind;
    EXPECT_EQ(one.size(), sphere.positions.size());
  }
}

TEST(Deformers, TwistRotatesAboutTheAxisByHeight) {
  const std::vector<Vec3f> rest = column();
  DeformerSpec s = spec_of("twist");
  s.angle_deg = 90.0f;
  const float t = 0.5f;  // the top has turned 45 degrees
  const std::vector<Vec3f> out = run(s, rest, t);
  const RestPose pose = measure_rest_pose(rest);
  const Vec3f m = pose.bounds.center();
  for (size_t i = 0; i < rest.size(); i += 97) {
    EXPECT_EQ(out[i].y, rest[i].y);
    const float r0 = std::hypot(rest[i].x - m.x, rest[i].z - m.z);
    const float r1 = std::hypot(out[i].x - m.x, out[i].z - m.z);
    EXPECT_NEAR(r0, r1, 1e-5f);
    const float h = (rest[i].y - pose.bounds.min.y) / (pose.bounds.max.y - pose.bounds.min.y);
    const float a0 = std::atan2(rest[i].x - m.x, rest[i].z - m.z);  // angle in the (z, x) plane
    const float a1 = std::atan2(out[i].x - m.x, out[i].z - m.z);
    float turned = a1 - a0;
    while (turned > kPi) turned -= 2 * kPi;
    while (turned < -kPi) turned += 2 * kPi;
    if (r0 > 0.05f) {
      EXPECT_NEAR(turned, 0.25f * kPi * h, 2e-4f) << i;
    }
  }
}

TEST(Deformers, BendRollsTheCentreLineOntoAnArc) {
  // A straight line along y through the centre of its bounds in x.
  std::vector<Vec3f> rest;
  for (int i = 0; i <= 100; ++i) rest.push_back({0.0f, float(i) * 0.02f, 0.3f});
  rest.push_back({-0.1f, 0.0f, 0.3f});  // give the bounds a width around x = 0
  rest.push_back({0.1f, 0.0f, 0.3f});
  DeformerSpec s = spec_of("bend");
  s.angle_deg = 90.0f;
  const std::vector<Vec3f> out = run(s, rest, 1.0f);  // total arc angle 90 degrees
  const float length = 2.0f, radius = length / (0.5f * kPi);
  // The centre of curvature is at (x = radius, y = 0); every centre-line point
  // stays at distance radius from it, at arc length = its rest height.
  for (int i = 0; i <= 100; ++i) {
    const Vec3f q = out[size_t(i)];
    EXPECT_NEAR(std::hypot(q.x - radius, q.y), radius, 1e-4f) << i;
    EXPECT_NEAR(std::atan2(q.y, radius - q.x) * radius, rest[size_t(i)].y, 1e-4f) << i;
    EXPECT_EQ(q.z, 0.3f);
  }
  EXPECT_NEAR(out[100].x, radius, 1e-4f);  // the top end now points along +x
  EXPECT_NEAR(out[100].y, radius, 1e-4f);
}

TEST(Deformers, WaveTravelsAndOnlyMovesItsAxis) {
  const std::vector<Vec3f> rest = column();
  DeformerSpec s = spec_of("wave");
  s.amplitude = 0.05f;
  s.wavelength = 0.5f;
  s.speed = 0.3f;
  const std::vector<Vec3f> a = run(s, rest, 0.2f);
  const std::vector<Vec3f> b = run(s, rest, 0.2f + 0.25f);  // the wave moved 0.075 along x
  const float lo_x = measure_rest_pose(rest).bounds.min.x;
  for (size_t i = 0; i < rest.size(); i += 31) {
    EXPECT_EQ(a[i].x, rest[i].x);
    EXPECT_EQ(a[i].z, rest[i].z);
    EXPECT_LE(std::abs(a[i].y - rest[i].y), s.amplitude * 1.0001f);
    const float expect =
        s.amplitude * std::sin(2 * kPi * (rest[i].x - lo_x - s.speed * 0.2f) / s.wavelength);
    EXPECT_NEAR(a[i].y - rest[i].y, expect, 1e-5f);
    // b at x equals a at x - 0.075: the same phase.
    const float shifted =
        s.amplitude *
        std::sin(2 * kPi * (rest[i].x - 0.075f - lo_x - s.speed * 0.2f) / s.wavelength);
    EXPECT_NEAR(b[i].y - rest[i].y, shifted, 1e-4f);
  }
}

TEST(Deformers, PulseKeepsTheCentroid) {
  const TriangleMesh torus = generate_torus(20000);
  DeformerSpec s = spec_of("pulse");
  s.amplitude = 0.3f;
  s.speed = 0.5f;
  const RestPose rest = measure_rest_pose(torus.positions);
  for (float t : {0.3f, 1.0f, 1.7f}) {
    const std::vector<Vec3f> out = run(s, torus.positions.to_vector(), t);
    const RestPose moved = measure_rest_pose(out);
    EXPECT_NEAR(moved.centroid.x, rest.centroid.x, 1e-5f);
    EXPECT_NEAR(moved.centroid.y, rest.centroid.y, 1e-5f);
    EXPECT_NEAR(moved.centroid.z, rest.centroid.z, 1e-5f);
    const float scale = 1.0f + s.amplitude * std::sin(2 * kPi * s.speed * t);
    const Vec3f d0 = torus.positions[123] - rest.centroid, d1 = out[123] - rest.centroid;
    EXPECT_NEAR(length(d1), length(d0) * scale, 1e-5f);
  }
}

TEST(Deformers, ExplodeMovesEachTriangleRigidlyAlongItsNormal) {
  TriangleMesh sphere = generate_sphere(5000);
  unweld(sphere);
  DeformerSpec s = spec_of("explode");
  s.amplitude = 0.4f;
  s.speed = 1.5f;
  const float t = 0.8f;
  const std::vector<Vec3f> out = run(s, sphere.positions.to_vector(), t);
  for (size_t tri = 0; tri < sphere.triangles.size(); ++tri) {
    const Vec3f* p = &sphere.positions[3 * tri];
    const Vec3f* q = &out[3 * tri];
    const Vec3f n = normalize(cross(p[1] - p[0], p[2] - p[0]));
    const Vec3f d = q[0] - p[0];
    for (int k = 1; k < 3; ++k) {  // the same offset for all three vertices: shape kept
      EXPECT_NEAR(length((q[k] - p[k]) - d), 0.0f, 1e-5f) << tri;
    }
    const float expect = s.amplitude * s.speed * t * explode_factor(tri);
    EXPECT_NEAR(dot(d, n), expect, 1e-4f) << tri;                // along the normal ...
    EXPECT_NEAR(length(d - n * dot(d, n)), 0.0f, 1e-4f) << tri;  // ... and only along it
    EXPECT_GT(dot(d, p[0]), 0.0f) << tri;                        // outward (the sphere's winding)
  }
}

TEST(Deformers, ExplodeFactorIsInRangeAndVaries) {
  float lo = 10.0f, hi = -10.0f;
  for (size_t i = 0; i < 10000; ++i) {
    lo = std::min(lo, explode_factor(i));
    hi = std::max(hi, explode_factor(i));
  }
  EXPECT_GE(lo, 0.5f);
  EXPECT_LT(hi, 1.5f);
  EXPECT_LT(lo, 0.51f);
  EXPECT_GT(hi, 1.49f);
}

TEST(Deformers, ExplodeNeedsAnUnweldedMesh) {
  std::vector<Vec3f> p(10, Vec3f(1.0f));
  EXPECT_THROW(run(spec_of("explode"), p, 1.0f), InputError);
  EXPECT_THROW(run(spec_of("melt"), p, 1.0f), InputError);
}

TEST(Deformers, UnweldKeepsTrianglesAndOrder) {
  TriangleMesh mesh = generate_torus(3000);
  mesh.normals.assign(mesh.positions.size(), Vec3f(0.0f, 1.0f, 0.0f));
  const TriangleMesh before = mesh;
  EXPECT_FALSE(is_unwelded(mesh));
  unweld(mesh);
  EXPECT_TRUE(is_unwelded(mesh));
  EXPECT_TRUE(mesh.padded_for_embree());
  ASSERT_EQ(mesh.triangles.size(), before.triangles.size());
  ASSERT_EQ(mesh.positions.size(), 3 * before.triangles.size());
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (size_t i = 0; i < before.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(mesh.positions[mesh.triangles[i][k]], before.positions[before.triangles[i][k]]);
}

}  // namespace
}  // namespace hprt
