// Local shading terms: Lambert, Blinn-Phong, ambient, mirror direction and the
// shadow segment of point and directional lights.
#include <gtest/gtest.h>

#include <cmath>

#include "render/shading.h"

namespace hprt {
namespace {

TEST(Shading, AmbientIsAmbientTimesDiffuse) {
  Material m;
  m.diffuse = Vec3f(0.8f, 0.5f, 0.25f);
  const Vec3f a = ambient_term(Vec3f(0.1f, 0.2f, 0.4f), m);
  EXPECT_FLOAT_EQ(a.x, 0.08f);
  EXPECT_FLOAT_EQ(a.y, 0.1f);
  EXPECT_FLOAT_EQ(a.z, 0.1f);
}

TEST(Shading, LambertIsCosineWeighted) {
  Material m;
  m.diffuse = Vec3f(0.5f, 0.6f, 0.7f);
  const Vec3f n(0.0f, 1.0f, 0.0f);
  const Vec3f v(0.0f, 1.0f, 0.0f);
  for (const float deg : {0.0f, 30.0f, 60.0f, 89.0f}) {
    const float a = deg * float(M_PI) / 180.0f;
    const Vec3f l(std::sin(a), std::cos(a), 0.0f);
    const Vec3f c = direct_term(m, n, l, v, Vec3f(2.0f));
    EXPECT_NEAR(c.x, 0.5f * std::cos(a) * 2.0f, 1e-6f) << deg;
    EXPECT_NEAR(c.z, 0.7f * std::cos(a) * 2.0f, 1e-6f) << deg;
  }
  // Light behind the surface: nothing, specular included.
  m.specular = Vec3f(1.0f);
  const Vec3f behind = direct_term(m, n, normalize(Vec3f(0.3f, -1.0f, 0.0f)), v, Vec3f(1.0f));
  EXPECT_EQ(behind, Vec3f(0.0f));
}

TEST(Shading, BlinnPhongPeaksAtMirrorDirection) {
  Material m;
  m.diffuse = Vec3f(0.0f);
  m.specular = Vec3f(1.0f);
  m.shininess = 50.0f;
  const Vec3f n(0.0f, 0.0f, 1.0f);
  const Vec3f l = normalize(Vec3f(1.0f, 0.0f, 1.0f));
  // Viewer at the mirror direction of l: h = n, full highlight.
  const Vec3f v_mirror = normalize(Vec3f(-1.0f, 0.0f, 1.0f));
  EXPECT_NEAR(direct_term(m, n, l, v_mirror, Vec3f(1.0f)).x, 1.0f, 1e-6f);
  // Elsewhere: max(0, n.h)^shininess exactly.
  const Vec3f v = normalize(Vec3f(0.0f, 0.3f, 1.0f));
  const Vec3f h = normalize(l + v);
  EXPECT_NEAR(direct_term(m, n, l, v, Vec3f(1.0f)).y, std::pow(dot(n, h), 50.0f), 1e-6f);
  EXPECT_LT(direct_term(m, n, l, v, Vec3f(1.0f)).y, 1.0f);
}

TEST(Shading, ReflectMirrorsAboutNormal) {
  const Vec3f d = normalize(Vec3f(1.0f, -1.0f, 0.0f));
  const Vec3f r = reflect(d, Vec3f(0.0f, 1.0f, 0.0f));
  EXPECT_NEAR(r.x, d.x, 1e-7f);
  EXPECT_NEAR(r.y, -d.y, 1e-7f);
  EXPECT_NEAR(length(r), 1.0f, 1e-6f);
}

TEST(Shading, ShadowSegmentEndsAtPointLight) {
  Light point;
  point.type = LightType::kPoint;
  point.position = Vec3f(1.0f, 5.0f, -2.0f);
  const Vec3f o(0.5f, 0.0f, 1.0f);
  const ShadowSegment s = shadow_segment(point, o);
  const Vec3f end = o + s.dir * s.tfar;
  EXPECT_NEAR(end.x, 1.0f, 1e-6f);
  EXPECT_NEAR(end.y, 5.0f, 1e-6f);
  EXPECT_NEAR(end.z, -2.0f, 1e-6f);
  EXPECT_NEAR(length(s.to_light), 1.0f, 1e-6f);

  Light sun;
  sun.type = LightType::kDirectional;
  sun.direction = Vec3f(0.0f, -2.0f, 0.0f);  // travels down: the light is up
  const ShadowSegment d = shadow_segment(sun, o);
  EXPECT_TRUE(std::isinf(d.tfar));
  EXPECT_NEAR(d.to_light.y, 1.0f, 1e-7f);
}

}  // namespace
}  // namespace hprt
