// rays_coherent: the 16-lane form (rays_coherent16, AVX-512) decides every
// group as the ray-by-ray tests do, on groups built to straddle each
// threshold (origin offset, direction cosine 0.9) and with each kind of
// invalid ray in the first, a middle and the last lane; and the transpose
// both it and packets read records through (load_ray_fields16).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/ray_coherence.h"

namespace hprt {
namespace {

constexpr size_t kGroup = 16;
constexpr float kOffset = 0.5f;

// Sixteen camera-like rays: one origin, directions within a few degrees.
std::vector<Ray> camera_group() {
  std::vector<Ray> r(kGroup);
  for (size_t i = 0; i < kGroup; ++i) {
    r[i].org = Vec3f(1.0f, 2.0f, 3.0f);
    r[i].dir = Vec3f(0.01f * float(i % 4), 0.01f * float(i / 4), -1.0f);
    r[i].tnear = 0.0f;
    r[i].tfar = std::numeric_limits<float>::infinity();
  }
  return r;
}

#if defined(__AVX512F__)
TEST(RayFields16, EveryFieldOfEveryRayInItsLane) {
  std::vector<Ray> r(kGroup);
  float* f = &r[0].org.x;
  for (size_t i = 0; i < 8 * kGroup; ++i) f[i] = float(i);  // field k of ray l: 8 l + k
  __m512 fields[8];
  load_ray_fields16(r.data(), fields);
  for (int k = 0; k < 8; ++k) {
    alignas(64) float lane[16];
    _mm512_store_ps(lane, fields[k]);
    for (int l = 0; l < 16; ++l) EXPECT_EQ(lane[l], float(8 * l + k)) << "field " << k;
  }
}
#endif

TEST(RayCoherence, CameraGroupIsCoherent) {
  const std::vector<Ray> r = camera_group();
  EXPECT_TRUE(rays_coherent(r.data(), kGroup, kOffset));
  EXPECT_TRUE(rays_coherent_each(r.data(), kGroup, kOffset));
}

TEST(RayCoherence, AnyInvalidLaneBreaksTheGroup) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const auto breakers = std::vector<void (*)(Ray&)>{
      [](Ray& r) { r.org.x = kNaN; },
      [](Ray& r) { r.org.z = 2e18f; },  // beyond kRayComponentLimit
      [](Ray& r) { r.dir.y = kInf; },
      [](Ray& r) { r.dir = Vec3f(0.0f); },
      [](Ray& r) { r.tnear = -1.0f; },
      [](Ray& r) { r.tnear = 2.0f, r.tfar = 1.0f; },
      [](Ray& r) { r.tfar = kNaN; },
      [](Ray& r) { r.org.y += 1.01f * kOffset; },         // origin too far
      [](Ray& r) { r.dir = Vec3f(0.0f, 0.5f, -0.5f); },   // 45 degrees off
      [](Ray& r) { r.dir = Vec3f(0.0f, 0.0f, 1.0f); },    // backwards
      [](Ray& r) { r.dir = Vec3f(1e-30f, 0.0f, 0.0f); },  // its length underflows: NaN
  };
  for (size_t b = 0; b < breakers.size(); ++b)
    for (const size_t lane : {size_t(0), size_t(7), size_t(15)}) {
      std::vector<Ray> r = camera_group();
      breakers[b](r[lane]);
      EXPECT_FALSE(rays_coherent(r.data(), kGroup, kOffset)) << "breaker " << b << " lane " << lane;
      EXPECT_FALSE(rays_coherent_each(r.data(), kGroup, kOffset))
          << "breaker " << b << " lane " << lane;
    }
}

TEST(RayCoherence, OriginOffsetExactlyAtTheBoundIsCoherent) {
  std::vector<Ray> r = camera_group();
  r[9].org.x = r[0].org.x + kOffset;  // 1.5: exact
  EXPECT_TRUE(rays_coherent(r.data(), kGroup, kOffset));
  EXPECT_TRUE(rays_coherent_each(r.data(), kGroup, kOffset));
}

// Random groups around both thresholds: the 16-lane form and the ray-by-ray
// tests agree on every one, and both answers occur. Directions whose cosine
// to the first lies within 1e-5 of 0.9 are redrawn: there the float
// rounding of either form may tip the decision, which only picks packet or
// single-ray tracing (both answer the same).
TEST(RayCoherence, SixteenLanesDecideAsRayByRay) {
  std::mt19937 rng(20261207);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_real_distribution<float> spread(0.0f, 1.2f * kOffset);
  std::uniform_real_distribution<double> angle(0.0, 0.55);  // cos 0.9 = 0.451 rad
  std::uniform_int_distribution<int> pick(0, 15);
  int coherent = 0, not_coherent = 0;
  for (int g = 0; g < 20000; ++g) {
    std::vector<Ray> r(kGroup);
    const Vec3f base{unit(rng) * 10.0f, unit(rng) * 10.0f, unit(rng) * 10.0f};
    Vec3f axis;
    do axis = Vec3f(unit(rng), unit(rng), unit(rng));
    while (!(length(axis) > 0.1f));
    axis = normalize(axis);
    // A unit vector perpendicular to the axis, to tilt directions by.
    const Vec3f side = normalize(std::fabs(axis.x) < 0.9f ? cross(axis, Vec3f(1, 0, 0))
                                                          : cross(axis, Vec3f(0, 1, 0)));
    const float scale = std::pow(10.0f, unit(rng) * 3.0f);  // direction lengths 1e-3..1e3
    for (size_t i = 0; i < kGroup; ++i) {
      r[i].org = i == 0 || g % 3 == 0 ? base : base + Vec3f(spread(rng), spread(rng), -spread(rng));
      for (;;) {
        const double a = i == 0 ? 0.0 : (g % 2 ? angle(rng) : 0.3 * angle(rng));
        const Vec3f d = axis * float(std::cos(a)) + side * float(std::sin(a));
        const double c = double(dot(normalize(d), axis));
        if (i > 0 && std::fabs(c - 0.9) < 1e-5) continue;
        r[i].dir = d * scale;
        break;
      }
      r[i].tnear = 0.0f;
      r[i].tfar = std::numeric_limits<float>::infinity();
    }
    if (g % 50 == 0) {  // some with an invalid ray
      Ray& bad = r[size_t(pick(rng))];
      bad.tnear = 3.0f, bad.tfar = 1.0f;
    }
    const bool each = rays_coherent_each(r.data(), kGroup, kOffset);
    ASSERT_EQ(rays_coherent(r.data(), kGroup, kOffset), each) << "group " << g;
    (each ? coherent : not_coherent)++;
  }
  EXPECT_GT(coherent, 1000);
  EXPECT_GT(not_coherent, 1000);
}

}  // namespace
}  // namespace hprt
