// Ray/triangle tests: known t/u/v (Embree's u,v convention), back faces,
// edges and vertices, the (tnear, tfar] interval, and watertightness along
// shared edges and at a shared vertex.
#include "bvh/intersect/ray_triangle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "tests/support/bvh_test_meshes.h"

namespace hprt {
namespace {

Ray make_ray(Vec3f o, Vec3f d, float tnear = 0.0f,
             float tfar = std::numeric_limits<float>::infinity()) {
  Ray r;
  r.org = o;
  r.dir = d;
  r.tnear = tnear;
  r.tfar = tfar;
  return r;
}

template <typename Test>
bool hit_test(const Ray& r, Vec3f a, Vec3f b, Vec3f c, TriangleHit& h) {
  const auto p = Test::prepare(r);
  if constexpr (std::is_same_v<Test, MollerTest>)
    return Test::intersect_vertices(p, a, b, c, r.tnear, r.tfar, h);
  else
    return Test::intersect(p, a, b, c, r.tnear, r.tfar, h);
}

template <typename T>
class TriangleTest : public ::testing::Test {};
using Tests = ::testing::Types<WatertightTest, MollerTest>;
TYPED_TEST_SUITE(TriangleTest, Tests);

const Vec3f kA{0, 0, 0}, kB{1, 0, 0}, kC{0, 1, 0};

TYPED_TEST(TriangleTest, KnownHitUsesEmbreeBarycentrics) {
  TriangleHit h{};
  ASSERT_TRUE(hit_test<TypeParam>(make_ray({0.25f, 0.5f, 2.0f}, {0, 0, -1}), kA, kB, kC, h));
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_FLOAT_EQ(h.u, 0.25f);  // weight of v1 = (1,0,0)
  EXPECT_FLOAT_EQ(h.v, 0.5f);   // weight of v2 = (0,1,0)
  // Not unit length and oblique: t scales with 1/|dir|.
  ASSERT_TRUE(hit_test<TypeParam>(make_ray({0.25f, 0.5f, 2.0f}, {0, 0, -4}), kA, kB, kC, h));
  EXPECT_FLOAT_EQ(h.t, 0.5f);
  ASSERT_TRUE(
      hit_test<TypeParam>(make_ray({-0.75f, 0.5f, 1.0f}, {1.0f, 0.0f, -1.0f}), kA, kB, kC, h));
  EXPECT_FLOAT_EQ(h.t, 1.0f);
  EXPECT_FLOAT_EQ(h.u, 0.25f);
  EXPECT_FLOAT_EQ(h.v, 0.5f);
}

TYPED_TEST(TriangleTest, BackFaceHitsAndMissesOutside) {
  TriangleHit h{};
  ASSERT_TRUE(hit_test<TypeParam>(make_ray({0.2f, 0.3f, -3.0f}, {0, 0, 1}), kA, kB, kC, h));
  EXPECT_FLOAT_EQ(h.t, 3.0f);
  EXPECT_FLOAT_EQ(h.u, 0.2f);
  EXPECT_FLOAT_EQ(h.v, 0.3f);
  EXPECT_FALSE(hit_test<TypeParam>(make_ray({0.6f, 0.6f, 1.0f}, {0, 0, -1}), kA, kB, kC, h));
  EXPECT_FALSE(hit_test<TypeParam>(make_ray({-0.1f, 0.5f, 1.0f}, {0, 0, -1}), kA, kB, kC, h));
  EXPECT_FALSE(hit_test<TypeParam>(make_ray({0.2f, 0.2f, 1.0f}, {0, 0, 1}), kA, kB, kC, h));
  // Parallel to the plane.
  EXPECT_FALSE(hit_test<TypeParam>(make_ray({-1.0f, 0.2f, 0.5f}, {1, 0, 0}), kA, kB, kC, h));
}

// Möller-Trumbore treats each triangle as closed: its edges and vertices hit.
// (The watertight test follows a fill rule instead: below.)
TEST(TriangleTestMoller, EdgesAndVerticesHit) {
  TriangleHit h{};
  const Vec3f pts[] = {{0.5f, 0.0f, 0}, {0.0f, 0.5f, 0}, {0.5f, 0.5f, 0},
                       {0, 0, 0},       {1, 0, 0},       {0, 1, 0}};
  for (const Vec3f& p : pts) {
    EXPECT_TRUE(hit_test<MollerTest>(make_ray(p + Vec3f{0, 0, 1}, {0, 0, -1}), kA, kB, kC, h))
        << p.x << "," << p.y;
    EXPECT_FLOAT_EQ(h.t, 1.0f);
  }
}

// How many of `tris` the ray hits with the watertight test.
int count_hits(const Ray& r, const std::vector<std::array<Vec3f, 3>>& tris) {
  int n = 0;
  for (const auto& t : tris) {
    TriangleHit h{};
    n += hit_test<WatertightTest>(r, t[0], t[1], t[2], h);
  }
  return n;
}

// A unit square as two triangles (either winding each): a ray exactly through
// a point of the shared diagonal hits exactly one of them, from either side,
// axis-parallel or oblique; a ray through the shared vertices of the four
// triangles of a square split by both diagonals hits exactly one.
TEST(TriangleTestWatertight, SharedEdgeAndVertexHitExactlyOnce) {
  const Vec3f p00{0, 0, 0}, p10{1, 0, 0}, p11{1, 1, 0}, p01{0, 1, 0}, mid{0.5f, 0.5f, 0};
  const Vec3f dirs[] = {{0, 0, -1},       {0, 0, 1},      {0.25f, -0.5f, -1}, {-3, 1, 2},
                        {0.5f, 0.5f, -1}, {-1, -1, 0.5f}, {1, 0, -0.125f},    {0, 1, 0.75f}};
  for (int winding = 0; winding < 4; ++winding) {
    std::vector<std::array<Vec3f, 3>> halves = {{p00, p10, p11}, {p00, p11, p01}};
    if (winding & 1) std::swap(halves[0][1], halves[0][2]);
    if (winding & 2) std::swap(halves[1][1], halves[1][2]);
    std::vector<std::array<Vec3f, 3>> quarters = {
        {p00, p10, mid}, {p10, p11, mid}, {p11, p01, mid}, {p01, p00, mid}};
    if (winding & 1) std::swap(quarters[0][0], quarters[0][1]);
    if (winding & 2) std::swap(quarters[2][0], quarters[2][1]);
    for (const Vec3f& d : dirs)
      for (int k = 1; k < 16; ++k) {
        const float s = float(k) / 16.0f;
        const Vec3f target{s, s, 0};
        const Ray from_side = make_ray(target - d * 3.0f, d);
        EXPECT_EQ(count_hits(from_side, halves), 1)
            << "winding " << winding << " dir " << d.x << "," << d.y << "," << d.z << " s " << s;
        const Ray at_mid = make_ray(mid - d * (1.0f + s), d);
        EXPECT_EQ(count_hits(at_mid, quarters), 1)
            << "winding " << winding << " dir " << d.x << "," << d.y << "," << d.z;
      }
  }
}

TYPED_TEST(TriangleTest, IntervalIsEmbreesOpenNearClosedFar) {
  TriangleHit h{};
  const Vec3f o{0.25f, 0.25f, 2.0f}, d{0, 0, -1};
  EXPECT_TRUE(hit_test<TypeParam>(make_ray(o, d, 0.0f, 2.0f), kA, kB, kC, h));  // t == tfar
  EXPECT_FALSE(hit_test<TypeParam>(make_ray(o, d, 0.0f, 1.999f), kA, kB, kC, h));
  EXPECT_TRUE(hit_test<TypeParam>(make_ray(o, d, 1.999f, 5.0f), kA, kB, kC, h));
  EXPECT_FALSE(hit_test<TypeParam>(make_ray(o, d, 2.0f, 5.0f), kA, kB, kC, h));  // t == tnear
  EXPECT_FALSE(hit_test<TypeParam>(make_ray(o, d, 2.5f, 5.0f), kA, kB, kC, h));
  // Behind the origin: negative t is outside [0, inf).
  EXPECT_FALSE(hit_test<TypeParam>(make_ray({0.25f, 0.25f, -2.0f}, d), kA, kB, kC, h));
}

// 16 triangles around a shared centre vertex; rays from random points above
// aimed at points of the shared edges and at the centre. The watertight test
// must hit at least one triangle for every ray; Möller-Trumbore is only
// reported (it can leak through edges).
TEST(TriangleTestWatertight, FanEdgesAndVertexNeverLeak) {
  constexpr int kFan = 16;
  const Vec3f centre{0.1f, -0.2f, 0.3f};
  std::vector<Vec3f> rim;
  for (int k = 0; k < kFan; ++k) {
    const float a = 2.0f * 3.14159265f * float(k) / kFan;
    rim.push_back(centre + Vec3f{std::cos(a), std::sin(a), 0.1f * std::sin(3.0f * a)});
  }
  test::Rng rng(7);
  int misses_wt = 0, misses_mt = 0, doubles_wt = 0;
  for (int i = 0; i < 10000; ++i) {
    const int k = i % kFan;
    const float s = (i % 10 == 0) ? 0.0f : 0.01f + 0.9f * rng.uniform();
    const Vec3f target = centre + (rim[k] - centre) * s;
    const Vec3f org{target.x + 2.0f * (rng.uniform() - 0.5f),
                    target.y + 2.0f * (rng.uniform() - 0.5f), 2.0f + rng.uniform()};
    const Ray r = make_ray(org, target - org);
    int hits_wt = 0;
    bool any_mt = false;
    for (int f = 0; f < kFan; ++f) {
      TriangleHit h{};
      const Vec3f& b = rim[f];
      const Vec3f& c = rim[(f + 1) % kFan];
      hits_wt += hit_test<WatertightTest>(r, centre, b, c, h);
      any_mt |= hit_test<MollerTest>(r, centre, b, c, h);
    }
    misses_wt += hits_wt == 0;
    doubles_wt += hits_wt > 1;
    misses_mt += !any_mt;
  }
  EXPECT_EQ(misses_wt, 0);
  EXPECT_EQ(doubles_wt, 0);  // the fan is crossed once: one triangle hit
  std::printf("[ info ] fan of %d, 10000 edge/vertex rays: watertight misses %d, MT misses %d\n",
              kFan, misses_wt, misses_mt);
}

TEST(TriangleTestWatertight, BarycentricsMatchMollerOnRandomHits) {
  test::Rng rng(3);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    auto p = [&] { return Vec3f{rng.uniform(), rng.uniform(), rng.uniform()}; };
    const Vec3f a = p(), b = p(), c = p();
    const float wu = rng.uniform() * 0.5f, wv = rng.uniform() * 0.5f;
    const Vec3f target = a * (1 - wu - wv) + b * wu + c * wv;
    const Vec3f org = p() * 4.0f - Vec3f{2, 2, 2};
    const Ray r = make_ray(org, target - org);
    TriangleHit hw{}, hm{};
    const bool w = hit_test<WatertightTest>(r, a, b, c, hw);
    const bool m = hit_test<MollerTest>(r, a, b, c, hm);
    if (!w || !m) continue;
    ++hits;
    EXPECT_NEAR(hw.t, 1.0f, 1e-3f);
    EXPECT_NEAR(hw.u, wu, 2e-3f);
    EXPECT_NEAR(hw.v, wv, 2e-3f);
    EXPECT_NEAR(hw.u, hm.u, 2e-3f);
    EXPECT_NEAR(hw.v, hm.v, 2e-3f);
  }
  EXPECT_GT(hits, 1800);
}

// prepare() and lane_bound() are written without branches; here they are
// checked field by field against the paper's axis choice and the bound's
// definition written out plainly, on directions with tied magnitudes, signed
// zeros and every sign, and on origins inside and outside the box.
TEST(TriangleTestWatertight, PreparedStateIsThePapersAxesAndTheBoxBound) {
  const float vals[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -2.0f, 3e-20f, -7e30f};
  const AABB box(Vec3f{-1.5f, 2.0f, -3e5f}, Vec3f{4.0f, 2.5f, 1e-3f});
  int checked = 0;
  for (float x : vals)
    for (float y : vals)
      for (float z : vals) {
        const Vec3f d{x, y, z};
        if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) continue;
        for (const Vec3f& o : {Vec3f{0.25f, 2.1f, -7.0f}, Vec3f{-9e6f, 3.0f, 5.0f}}) {
          const Ray r = make_ray(o, d);
          const WatertightTest::Prepared p = WatertightTest::prepare(r, box);
          const Vec3f a{std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)};
          int kz = a.x >= a.y ? (a.x >= a.z ? 0 : 2) : (a.y >= a.z ? 1 : 2);
          int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
          if (d[kz] < 0.0f) std::swap(kx, ky);
          ASSERT_EQ(p.kz, kz);
          ASSERT_EQ(p.kx, kx);
          ASSERT_EQ(p.ky, ky);
          ASSERT_EQ(p.ox, double(o[kx]));
          ASSERT_EQ(p.oy, double(o[ky]));
          ASSERT_EQ(p.oz, double(o[kz]));
          ASSERT_EQ(p.sz, 1.0 / double(d[kz]));
          ASSERT_EQ(p.sx, double(d[kx]) * p.sz);
          ASSERT_EQ(p.sy, double(d[ky]) * p.sz);
          float m = 0.0f;
          for (int k = 0; k < 3; ++k)
            m = std::max({m, std::fabs(box.max[k] - o[k]), std::fabs(box.min[k] - o[k])});
          ASSERT_EQ(p.lane_bound, std::fma(0x1p-47 * (2.0 * m), 2.0 * m, 0x1p-900));
          ++checked;
        }
      }
  EXPECT_EQ(checked, 2 * (8 * 8 * 8 - 8));
  // Packets pass the box of their origins: the largest distance may pair
  // the box's minimum with the origins' maximum (y: |-50 - 9|) or its
  // maximum with their minimum (x: |4 - -200|).
  const AABB wide_y(Vec3f{-1.5f, -50.0f, -3.0f}, Vec3f{4.0f, 2.5f, 1e-3f});
  const Vec3f lo{-20.0f, 0.0f, 0.0f}, hi{0.0f, 9.0f, 0.0f};
  EXPECT_EQ(WatertightTest::lane_bound(lo, hi, wide_y), std::fma(0x1p-47 * 118.0, 118.0, 0x1p-900));
  EXPECT_EQ(WatertightTest::lane_bound(Vec3f{-200.0f, 0.0f, 0.0f}, hi, wide_y),
            std::fma(0x1p-47 * 408.0, 408.0, 0x1p-900));
  EXPECT_EQ(WatertightTest::lane_bound(lo, hi, AABB{}), HUGE_VAL);
}

}  // namespace
}  // namespace hprt
