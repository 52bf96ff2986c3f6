// Robust slab test: axis-parallel rays with ±0 components, origins on slab
// planes, NaN never hitting, grazing hits and the conservative far bound.
#include "bvh/intersect/ray_box.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bvh/traverse/traverse_bvh2.h"

namespace hprt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
const AABB kBox{{0, 0, 0}, {1, 1, 1}};

bool hits(const AABB& box, Vec3f org, Vec3f dir, float tmin = 0.0f, float tmax = kInf) {
  Ray r;
  r.org = org;
  r.dir = dir;
  const SlabRay s(r);
  const BoxFloats b = box_floats(box);
  float entry = 0;
  return slab_robust(s, b.f, tmin, tmax, entry);
}

TEST(SlabTest, AxisParallelWithSignedZeros) {
  for (float zy : {0.0f, -0.0f})
    for (float zz : {0.0f, -0.0f}) {
      EXPECT_TRUE(hits(kBox, {-1, 0.5f, 0.5f}, {1, zy, zz}));
      EXPECT_TRUE(hits(kBox, {2, 0.5f, 0.5f}, {-1, zy, zz}));
      EXPECT_FALSE(hits(kBox, {2, 0.5f, 0.5f}, {1, zy, zz}));     // pointing away
      EXPECT_FALSE(hits(kBox, {-1, 1.5f, 0.5f}, {1, zy, zz}));    // parallel, outside y slab
      EXPECT_FALSE(hits(kBox, {-1, 0.5f, -0.5f}, {1, zy, zz}));   // parallel, outside z slab
      EXPECT_TRUE(hits(kBox, {0.5f, 0.5f, 0.5f}, {zy, 1, zz}));   // inside
      EXPECT_TRUE(hits(kBox, {0.5f, -3.0f, 0.5f}, {zy, 2, zz}));  // along y
      EXPECT_FALSE(hits(kBox, {0.5f, -3.0f, 0.5f}, {zy, -2, zz}));
    }
}

TEST(SlabTest, OriginsOnSlabPlanesCountAsInside) {
  // Direction zero along x and the origin exactly on the min or max x plane:
  // (plane - org) * inf = 0 * inf = NaN must not decide the result.
  for (float zx : {0.0f, -0.0f}) {
    EXPECT_TRUE(hits(kBox, {0.0f, 0.5f, -1.0f}, {zx, 0, 1}));
    EXPECT_TRUE(hits(kBox, {1.0f, 0.5f, -1.0f}, {zx, 0, 1}));
    EXPECT_TRUE(hits(kBox, {1.0f, 1.0f, -1.0f}, {zx, 0, 1}));  // along a box edge
    EXPECT_TRUE(hits(kBox, {0.0f, 0.0f, 0.0f}, {zx, 0, 1}));   // from a corner
    EXPECT_FALSE(hits(kBox, {1.0f, 1.0f, -1.0f}, {zx, 0, -1}));
  }
  // Origin on a face, pointing out of the box: the entry point is the origin.
  EXPECT_TRUE(hits(kBox, {0.0f, 0.5f, 0.5f}, {-1, 0, 0}));
  EXPECT_FALSE(hits(kBox, {0.0f, 0.5f, 0.5f}, {-1, 0, 0}, 1e-3f));
}

TEST(SlabTest, NanNeverHits) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(hits(kBox, {0.5f, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, nan));
  EXPECT_FALSE(hits(kBox, {0.5f, 0.5f, 0.5f}, {1, 0, 0}, nan, nan));
  // NaN origins/directions drop every slab, so such rays are rejected once
  // per ray before traversal (ray_is_valid), never per box.
  Ray bad;
  bad.org = {-1, 0.5f, 0.5f};
  bad.dir = {nan, 0, 0};
  EXPECT_FALSE(ray_is_valid(bad));
  bad.dir = {1, 0, 0};
  bad.org = {nan, 0.5f, 0.5f};
  EXPECT_FALSE(ray_is_valid(bad));
  // A NaN in one direction component of an otherwise valid ray cannot occur
  // (invalid); a NaN slab *distance* (0 * inf) is the only NaN the test sees.
  // An empty box (the AABB default) is never hit.
  EXPECT_FALSE(hits(AABB{}, {0, 0, 0}, {1, 1, 1}));
}

TEST(SlabTest, GrazingAndIntervals) {
  // A ray skimming the top face (y = 1) at a shallow angle.
  EXPECT_TRUE(hits(kBox, {-1.0f, 1.0f, 0.5f}, {1.0f, 0.0f, 0.0f}));
  EXPECT_TRUE(hits(kBox, {-1.0f, 1.001f, 0.5f}, {1.0f, -0.001f, 0.0f}));
  EXPECT_FALSE(hits(kBox, {-1.0f, 1.001f, 0.5f}, {1.0f, 0.0f, 0.0f}));
  // tmax before the box, tmin after it.
  EXPECT_FALSE(hits(kBox, {-1, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 0.5f));
  EXPECT_TRUE(hits(kBox, {-1, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 1.0f));
  EXPECT_FALSE(hits(kBox, {-1, 0.5f, 0.5f}, {1, 0, 0}, 2.5f, kInf));
  EXPECT_TRUE(hits(kBox, {-1, 0.5f, 0.5f}, {1, 0, 0}, 2.0f, kInf));
  Ray r;
  r.org = {-1, 0.5f, 0.5f};
  r.dir = {2, 0, 0};
  const SlabRay s(r);
  float entry = -1;
  ASSERT_TRUE(slab_robust(s, box_floats(kBox).f, 0.0f, kInf, entry));
  // The entry distance is a lower bound of the exact 0.5, within the padding.
  EXPECT_LE(entry, 0.5f);
  EXPECT_GE(entry, 0.5f * (1.0f - 2.0f * float_gamma(3)));
  // So a box whose face lies exactly at tmax is still hit.
  EXPECT_TRUE(slab_robust(s, box_floats(kBox).f, 0.0f, 0.5f, entry));
}

// A box entered exactly at the closest hit so far (tmax) is never culled by
// rounding of the near distance: rays aimed at points of the near face.
TEST(SlabTest, NearFaceAtTmaxIsKept) {
  const AABB box{{0.1f, 0.3f, -0.7f}, {0.9f, 1.7f, 0.123f}};
  int culled = 0;
  for (int i = 0; i < 4000; ++i) {
    const float s = float(i % 61) / 61.0f, q = float(i % 53) / 53.0f;
    const Vec3f target{box.min.x, box.min.y + s * (box.max.y - box.min.y),
                       box.min.z + q * (box.max.z - box.min.z)};
    const Vec3f org = target - Vec3f{1.0f + 0.37f * q, 0.3f * (s - 0.5f), 0.21f * (q - 0.4f)};
    Ray r;
    r.org = org;
    r.dir = target - org;  // the face is reached at t = 1 (up to rounding of dir)
    const SlabRay sr(r);
    const double exact = (double(box.min.x) - double(org.x)) / double(r.dir.x);
    float entry = 0.0f;
    const bool hit = slab_robust(sr, box_floats(box).f, 0.0f, float(exact), entry);
    culled += !hit || double(entry) > exact;
  }
  EXPECT_EQ(culled, 0);
}

// Rays aimed at points of a box edge from many directions: rounding in the
// far distances must never turn the touching ray into a miss (Ize 2013).
TEST(SlabTest, ConservativeBoundKeepsEdgeHits) {
  const AABB box{{0.1f, 0.3f, -0.7f}, {0.9f, 1.7f, 0.123f}};
  int misses = 0;
  for (int i = 0; i < 4000; ++i) {
    const float s = float(i) / 4000.0f;
    // Point on the edge (x = max, y = max), z along the edge.
    const Vec3f target{box.max.x, box.max.y, box.min.z + s * (box.max.z - box.min.z)};
    const float a = 0.001f + 1.5f * float(i % 97) / 97.0f;
    const Vec3f org = target + Vec3f{3.0f * std::cos(a), 3.0f * std::sin(a), 0.37f * (s - 0.5f)};
    misses += !hits(box, org, target - org);
  }
  EXPECT_EQ(misses, 0);
}

TEST(SlabTest, GammaMatchesPbrt) {
  EXPECT_FLOAT_EQ(float_gamma(3), 3.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f));
  EXPECT_GT(1.0f + 2.0f * float_gamma(3), 1.0f);
}

#if defined(__AVX2__)
// The AVX2 two-box version must agree with two scalar calls bit for bit,
// including ±0 directions and origins on slab planes.
TEST(SlabTest, PairVersionEqualsScalar) {
  alignas(32) float boxes[2][8];
  uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return int((state >> 33) % 5);  // small integers: lots of exact plane hits
  };
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    for (auto& b : boxes) {
      for (int a = 0; a < 3; ++a) {
        const float lo = float(next()) - 2.0f, ext = float(next());
        b[a] = lo;
        b[4 + a] = lo + ext;
      }
      b[3] = b[7] = 1e30f;  // garbage in the index/count slots must not matter
    }
    Ray r;
    const float dirs[5] = {-1.0f, -0.0f, 0.0f, 0.5f, 2.0f};
    r.org = {float(next()) - 2.0f, float(next()) - 2.0f, float(next()) - 2.0f};
    r.dir = {dirs[next()], dirs[next()], dirs[next()]};
    if (r.dir.x == 0 && r.dir.y == 0 && r.dir.z == 0) continue;
    const float tmax = next() == 0 ? 1.0f : kInf;
    const SlabRay s(r);
    const SlabRayPair p(s);
    float e0 = 0, e1 = 0, p0 = 0, p1 = 0;
    const bool h0 = slab_robust(s, boxes[0], 0.0f, tmax, e0);
    const bool h1 = slab_robust(s, boxes[1], 0.0f, tmax, e1);
    const int m = slab_robust_pair(p, boxes[0], boxes[1], 0.0f, tmax, p0, p1);
    ASSERT_EQ(h0, bool(m & 1)) << i;
    ASSERT_EQ(h1, bool(m & 2)) << i;
    if (h0) {
      EXPECT_EQ(e0, p0);
    }
    if (h1) {
      EXPECT_EQ(e1, p1);
    }
    hits += h0 + h1;
  }
  EXPECT_GT(hits, 2000);
}
#endif

}  // namespace
}  // namespace hprt
