// Wächter & Binder ray origin offset: the offset point lies strictly on the
// normal's side of the surface plane at every scale, and close to it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/ray_offset.h"

namespace hprt {
namespace {

// Signed distance of q from the plane through p with unit normal n, in double.
double side(const Vec3f& p, const Vec3f& n, const Vec3f& q) {
  return dot(Vec3d(q) - Vec3d(p), Vec3d(n));
}

TEST(RayOffset, OffsetPointOnNormalSideAtEveryScale) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (const float scale : {0.0f, 1e-6f, 1.0f, 1e6f}) {
    for (int i = 0; i < 2000; ++i) {
      const Vec3f p = Vec3f(u(rng), u(rng), u(rng)) * scale;
      Vec3f n(u(rng), u(rng), u(rng));
      if (length(n) < 1e-3f) continue;
      n = normalize(n);
      const Vec3f q = offset_ray(p, n);
      EXPECT_GT(side(p, n, q), 0.0)
          << "scale " << scale << " p " << p.x << "," << p.y << "," << p.z;
      const Vec3f q_back = offset_ray(p, -n);
      EXPECT_LT(side(p, n, q_back), 0.0) << "scale " << scale;
    }
  }
}

TEST(RayOffset, AxisAlignedNormalsAtEveryScale) {
  for (const float scale : {0.0f, 1e-6f, 1.0f, 1e6f}) {
    for (int axis = 0; axis < 3; ++axis) {
      for (const float sign : {1.0f, -1.0f}) {
        for (const float ps : {1.0f, -1.0f}) {
          const Vec3f p(ps * scale, -ps * scale * 0.5f, ps * scale * 0.25f);
          Vec3f n(0.0f);
          n[axis] = sign;
          const Vec3f q = offset_ray(p, n);
          EXPECT_GT((q[axis] - p[axis]) * sign, 0.0f) << "scale " << scale << " axis " << axis;
          for (int other = 0; other < 3; ++other) {
            if (other != axis) {
              EXPECT_EQ(q[other], p[other]);
            }
          }
        }
      }
    }
  }
}

TEST(RayOffset, OffsetIsSmallRelativeToScale) {
  const Vec3f n = normalize(Vec3f(1.0f, 2.0f, 3.0f));
  // Near the origin: the fixed float offset 1/65536 per unit normal.
  const Vec3f q0 = offset_ray(Vec3f(0.0f), n);
  EXPECT_NEAR(length(q0), 1.0f / 65536.0f, 1e-9f);
  // At 1e6 (ulp 0.0625): at most 256 ulps per component = 16 units, and at
  // least one ulp in each component the normal has a part in.
  const Vec3f p(1e6f, -1e6f, 1e6f);
  const Vec3f q = offset_ray(p, n);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NE(q[k], p[k]);
    EXPECT_LE(std::fabs(q[k] - p[k]), 256.0f * 0.0625f);
  }
  // At 1: ulp 1.19e-7, 256 ulps ~ 3e-5.
  const Vec3f q1 = offset_ray(Vec3f(1.0f), n);
  EXPECT_LT(length(q1 - Vec3f(1.0f)), 1e-4f);
}

}  // namespace
}  // namespace hprt
