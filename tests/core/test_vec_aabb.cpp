// The vector and box types every layer builds on, and the splitmix64
// generator whose numbers generated meshes and ray sets depend on.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/aabb.h"
#include "core/splitmix64.h"
#include "core/vec.h"

namespace hprt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

TEST(Vec3, ArithmeticIsComponentWise) {
  const Vec3f a{1.0f, -2.0f, 3.0f}, b{0.5f, 4.0f, -1.0f};
  EXPECT_EQ(a + b, Vec3f(1.5f, 2.0f, 2.0f));
  EXPECT_EQ(a - b, Vec3f(0.5f, -6.0f, 4.0f));
  EXPECT_EQ(a * b, Vec3f(0.5f, -8.0f, -3.0f));
  EXPECT_EQ(a / b, Vec3f(2.0f, -0.5f, -3.0f));
  EXPECT_EQ(a * 2.0f, Vec3f(2.0f, -4.0f, 6.0f));
  EXPECT_EQ(2.0f * a, a * 2.0f);
  EXPECT_EQ(a / 2.0f, Vec3f(0.5f, -1.0f, 1.5f));
  EXPECT_EQ(-a, Vec3f(-1.0f, 2.0f, -3.0f));
  Vec3f c = a;
  c += b;
  EXPECT_EQ(c, a + b);
  c -= b;
  EXPECT_EQ(c, a);
  c *= 3.0f;
  EXPECT_EQ(c, a * 3.0f);
  EXPECT_EQ(a[0], 1.0f);
  EXPECT_EQ(a[1], -2.0f);
  EXPECT_EQ(a[2], 3.0f);
  c[1] = 7.0f;
  EXPECT_EQ(c.y, 7.0f);
  EXPECT_EQ(Vec3f(2.0f), Vec3f(2.0f, 2.0f, 2.0f));
  EXPECT_EQ(Vec3d(Vec3f(0.1f, 0.2f, 0.3f)).x, double(0.1f));
}

TEST(Vec3, DotCrossLengthNormalize) {
  const Vec3f x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  EXPECT_EQ(cross(x, y), z);
  EXPECT_EQ(cross(y, z), x);
  EXPECT_EQ(cross(z, x), y);
  EXPECT_EQ(cross(y, x), -z);
  EXPECT_EQ(dot(Vec3f(1, 2, 3), Vec3f(4, -5, 6)), 12.0f);
  EXPECT_EQ(length(Vec3f(3, 4, 12)), 13.0f);
  const Vec3d n = normalize(Vec3d(3, 4, 12));
  EXPECT_NEAR(length(n), 1.0, 1e-15);
  EXPECT_NEAR(n.z, 12.0 / 13.0, 1e-15);
  const Vec3f a{0.3f, -1.7f, 2.9f}, b{-4.1f, 0.2f, 1.3f};
  EXPECT_NEAR(dot(cross(a, b), a), 0.0f, 1e-5f);
  EXPECT_NEAR(dot(cross(a, b), b), 0.0f, 1e-5f);
}

TEST(Vec3, MinMaxFiniteAndLargestComponent) {
  const Vec3f a{1, 5, -3}, b{2, -1, -3};
  EXPECT_EQ(min(a, b), Vec3f(1, -1, -3));
  EXPECT_EQ(max(a, b), Vec3f(2, 5, -3));
  EXPECT_EQ(max_component(a), 5.0f);
  EXPECT_EQ(max_component(Vec3f(-1, -2, -0.5f)), -0.5f);
  EXPECT_TRUE(is_finite(a));
  EXPECT_FALSE(is_finite(Vec3f(1, kInf, 0)));
  EXPECT_FALSE(is_finite(Vec3f(kNaN, 0, 0)));
  EXPECT_FALSE(is_finite(Vec3f(0, 0, -kInf)));
}

TEST(Vec3u, IndexingAndEquality) {
  Vec3u t{{1, 2, 3}};
  EXPECT_EQ(t[0], 1u);
  EXPECT_EQ(t[2], 3u);
  t[1] = 9;
  EXPECT_EQ(t, (Vec3u{{1, 9, 3}}));
  EXPECT_NE(t, (Vec3u{{1, 2, 3}}));
}

TEST(AABB, EmptyBoxIsTheIdentityOfExtend) {
  const AABB empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_EQ(empty.half_area(), 0.0f);
  EXPECT_EQ(empty.surface_area(), 0.0f);
  AABB b;
  b.extend(Vec3f(1, 2, 3));
  EXPECT_FALSE(b.empty());
  EXPECT_EQ(b.min, Vec3f(1, 2, 3));
  EXPECT_EQ(b.max, Vec3f(1, 2, 3));
  EXPECT_EQ(b.half_area(), 0.0f);  // a point
  AABB c = b;
  c.extend(empty);
  EXPECT_EQ(c, b);
  AABB d;
  d.extend(b);
  EXPECT_EQ(d, b);
  EXPECT_TRUE(b.contains(empty));
  EXPECT_FALSE(empty.contains(Vec3f(0.0f)));
}

TEST(AABB, AreaCentreDiagonalAndContainment) {
  AABB b;
  b.extend(Vec3f(-1, 0, 2));
  b.extend(Vec3f(1, 3, 6));
  EXPECT_EQ(b.diagonal(), Vec3f(2, 3, 4));
  EXPECT_EQ(b.center(), Vec3f(0, 1.5f, 4));
  EXPECT_EQ(b.half_area(), 2.0f * 3 + 3 * 4 + 4 * 2);
  EXPECT_EQ(b.surface_area(), 2.0f * b.half_area());
  EXPECT_TRUE(b.contains(Vec3f(0, 0, 2)));  // on a face
  EXPECT_TRUE(b.contains(Vec3f(1, 3, 6)));  // a corner
  EXPECT_FALSE(b.contains(Vec3f(1.0001f, 1, 3)));
  EXPECT_TRUE(b.contains(AABB(Vec3f(0, 1, 3), Vec3f(1, 3, 6))));
  EXPECT_FALSE(b.contains(AABB(Vec3f(0, 1, 3), Vec3f(1, 3, 6.5f))));
  // A flat box has area, not volume.
  const AABB flat(Vec3f(0, 0, 0), Vec3f(2, 3, 0));
  EXPECT_FALSE(flat.empty());
  EXPECT_EQ(flat.half_area(), 6.0f);
  // Inverted on one axis: empty.
  EXPECT_TRUE(AABB(Vec3f(0, 0, 0), Vec3f(1, -1, 1)).empty());
}

TEST(SplitMix64, MatchesTheReferenceSequence) {
  // The first outputs of the reference generator seeded with 1234567
  // (Vigna's splitmix64.c): meshes and ray sets depend on these numbers.
  SplitMix64 rng(1234567);
  EXPECT_EQ(rng.next(), 6457827717110365317ull);
  EXPECT_EQ(rng.next(), 3203168211198807973ull);
  EXPECT_EQ(rng.next(), 9817491932198370423ull);
  EXPECT_EQ(splitmix64(1234567), 6457827717110365317ull);
  EXPECT_EQ(splitmix64_mix(1234567 + kSplitMixGamma), 6457827717110365317ull);
}

TEST(SplitMix64, UniformBelowAndCoin) {
  SplitMix64 rng(99);
  int heads = 0;
  for (int i = 0; i < 10000; ++i) {
    const float u = rng.uniform();
    EXPECT_GE(u, 0.0f);
    EXPECT_LT(u, 1.0f);
    EXPECT_LT(rng.below(7), 7u);
    heads += rng.coin();
  }
  EXPECT_NEAR(heads, 5000, 300);
}

}  // namespace
}  // namespace hprt
