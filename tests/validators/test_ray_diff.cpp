// Ray diff classification on hand-made answers (agree, tie, mismatches with
// each winner, occlusion) and an end-to-end bvh vs embree run on a sphere.
#include <gtest/gtest.h>

#include <vector>

#include "backends/intersector.h"
#include "core/parallel.h"
#include "meshgen/mesh_generators.h"
#include "validators/ray_diff.h"
#include "validators/ray_sets.h"

namespace hprt {
namespace {

// Two unit squares (each split along its diagonal (0,0)-(1,1)): geomID 0 at
// z = 0 and geomID 1 at z = 1.
Scene two_squares() {
  Scene s;
  for (float z : {0.0f, 1.0f}) {
    TriangleMesh m;
    m.positions = {{0, 0, z}, {1, 0, z}, {1, 1, z}, {0, 1, z}};
    Vec3u t0, t1;
    t0.v[0] = 0, t0.v[1] = 1, t0.v[2] = 2;
    t1.v[0] = 0, t1.v[1] = 2, t1.v[2] = 3;
    m.triangles = {t0, t1};
    s.add_mesh(m);
  }
  return s;
}

Ray ray_down(float x, float y) {
  Ray r;
  r.org = {x, y, 5.0f};
  r.dir = {0, 0, -1};
  return r;
}

Hit hit(uint32_t geom, uint32_t prim, float t) {
  Hit h;
  h.t = t;
  h.geom_id = geom;
  h.prim_id = prim;
  return h;
}

const Hit kMiss{};

struct Case {
  Ray ray;
  Hit bvh, embree;
  RayVerdict expected;
};

TEST(RayDiff, ClassifiesHandMadeAnswers) {
  const Scene s = two_squares();
  const std::vector<Case> cases = {
      {ray_down(0.75f, 0.25f), hit(1, 0, 4.0f), hit(1, 0, 4.0f), RayVerdict::kAgree},
      {ray_down(1.5f, 0.5f), kMiss, kMiss, RayVerdict::kAgree},
      // Through the shared diagonal: both triangles at t = 4.
      {ray_down(0.5f, 0.5f), hit(1, 0, 4.0f), hit(1, 1, 4.0f), RayVerdict::kTie},
      // Same t, different triangle, but (1, 1) is not hit: embree is wrong.
      {ray_down(0.75f, 0.25f), hit(1, 0, 4.0f), hit(1, 1, 4.0f), RayVerdict::kBvhRight},
      // bvh misses a hit in the middle of a triangle.
      {ray_down(0.75f, 0.25f), kMiss, hit(1, 0, 4.0f), RayVerdict::kEmbreeRight},
      // embree reports a hit on a ray that misses everything.
      {ray_down(1.5f, 0.5f), kMiss, hit(1, 0, 4.0f), RayVerdict::kBvhRight},
      // bvh reports the farther square (t = 5) behind the closer one (t = 4).
      {ray_down(0.25f, 0.75f), hit(0, 1, 5.0f), hit(1, 1, 4.0f), RayVerdict::kEmbreeRight},
      // Right triangle, wrong t; the other misses: both wrong.
      {ray_down(0.75f, 0.25f), hit(1, 0, 4.5f), kMiss, RayVerdict::kBothWrong},
      // A miss through the shared edge is a leak, not float resolution.
      {ray_down(0.5f, 0.5f), kMiss, hit(1, 1, 4.0f), RayVerdict::kEmbreeRight},
  };
  std::vector<Ray> rays;
  std::vector<Hit> hb, he;
  for (const Case& c : cases) {
    rays.push_back(c.ray);
    hb.push_back(c.bvh);
    he.push_back(c.embree);
  }
  for (size_t limit : {size_t(0), size_t(1000)}) {  // candidates only, brute force
    RayDiffOptions o;
    o.brute_force_limit = limit;
    const RayDiffResult r = diff_hits(s, rays, hb, he, o);
    EXPECT_EQ(r.brute_force, limit > 0);
    ASSERT_EQ(r.verdicts.size(), cases.size());
    for (size_t i = 0; i < cases.size(); ++i) {
      // Without brute force the leak's second triangle is no candidate, so a
      // miss on the edge of the one hit triangle is within float resolution.
      const RayVerdict want = limit == 0 && i == 8 ? RayVerdict::kBothRight : cases[i].expected;
      EXPECT_EQ(int(r.verdicts[i]), int(want)) << "case " << i << " limit " << limit;
    }
  }
  const RayDiffResult r = diff_hits(s, rays, hb, he);
  EXPECT_EQ(r.rays, cases.size());
  EXPECT_EQ(r.agree, 2u);
  EXPECT_EQ(r.ties, 1u);
  EXPECT_EQ(r.mismatches, 6u);
  EXPECT_EQ(r.bvh_right, 2u);
  EXPECT_EQ(r.embree_right, 3u);
  EXPECT_EQ(r.both_wrong, 1u);
  EXPECT_EQ(r.bvh_wrong(), 4u);
  EXPECT_EQ(r.mismatch_indices, (std::vector<size_t>{3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(r.max_rel_t_error, 0.0);
}

// A fold seen edge-on: triangle 0 in z = 0 over 0 <= y <= 1 - 2|x - 0.5|,
// triangle 1 sharing its edge on the x axis but hanging steeply down (far
// vertex at y = 1e-3, z = -0.04), so from above both cover the strip beside
// the edge and nothing covers y < 0. Rays down at y = 1e-6 (inside both,
// within the edge tolerance, t 4e-5 apart) and at y = 0 (on the shared edge)
// touch a silhouette: nearby rays pass outside, so a miss is within float
// resolution. Across the diagonal of a flat square, a ray 1e-7 off the shared
// edge crosses the surface whichever side it falls: a miss is a leak.
TEST(RayDiff, FoldSeenEdgeOnMayBeMissedButNotAFlatEdge) {
  Scene s;
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}, {0.5f, 1e-3f, -0.04f}};
  Vec3u t0, t1;
  t0.v[0] = 0, t0.v[1] = 1, t0.v[2] = 2;
  t1.v[0] = 1, t1.v[1] = 0, t1.v[2] = 3;
  m.triangles = {t0, t1};
  s.add_mesh(m);
  const std::vector<Ray> rays = {ray_down(0.5f, 1e-6f), ray_down(0.5f, 0.0f)};
  const std::vector<Hit> bvh = {kMiss, kMiss};
  const std::vector<Hit> embree = {hit(0, 0, 5.0f), hit(0, 0, 5.0f)};
  const RayDiffResult r = diff_hits(s, rays, bvh, embree);
  ASSERT_EQ(r.verdicts.size(), 2u);
  EXPECT_EQ(int(r.verdicts[0]), int(RayVerdict::kBothRight));
  EXPECT_EQ(int(r.verdicts[1]), int(RayVerdict::kBothRight));

  const Scene flat = two_squares();
  const std::vector<Ray> near_edge = {ray_down(0.5f + 1e-7f, 0.5f)};
  const RayDiffResult f =
      diff_hits(flat, near_edge, std::vector<Hit>{kMiss}, std::vector<Hit>{hit(1, 0, 4.0f)});
  ASSERT_EQ(f.verdicts.size(), 1u);
  EXPECT_EQ(int(f.verdicts[0]), int(RayVerdict::kEmbreeRight));
}

TEST(RayDiff, RelativeTTolerance) {
  const Scene s = two_squares();
  const std::vector<Ray> rays = {ray_down(0.75f, 0.25f)};
  // 4 * (1 + 2e-6): within 1e-5 -> agree, and the error is recorded.
  const std::vector<Hit> a = {hit(1, 0, 4.000008f)}, b = {hit(1, 0, 4.0f)};
  const RayDiffResult r = diff_hits(s, rays, a, b);
  EXPECT_EQ(r.agree, 1u);
  EXPECT_NEAR(r.max_rel_t_error, 2e-6, 1e-7);
  // 4 * (1 + 1e-4): a mismatch, and only embree is right.
  const std::vector<Hit> c = {hit(1, 0, 4.0004f)};
  const RayDiffResult r2 = diff_hits(s, rays, c, b);
  EXPECT_EQ(r2.embree_right, 1u);
}

TEST(RayDiff, Occlusion) {
  const Scene s = two_squares();
  const std::vector<Ray> rays = {ray_down(0.75f, 0.25f), ray_down(1.5f, 0.5f),
                                 ray_down(0.75f, 0.25f), ray_down(1.5f, 0.5f),
                                 ray_down(0.5f, 0.5f)};
  const std::vector<uint8_t> bvh = {1, 0, 0, 1, 1}, embree = {1, 0, 1, 0, 0};
  const RayDiffResult r = diff_occlusion(s, rays, bvh, embree);
  EXPECT_EQ(r.agree, 2u);
  EXPECT_EQ(int(r.verdicts[2]), int(RayVerdict::kEmbreeRight));
  EXPECT_EQ(int(r.verdicts[3]), int(RayVerdict::kEmbreeRight));
  EXPECT_EQ(int(r.verdicts[4]), int(RayVerdict::kBvhRight));
  EXPECT_EQ(r.bvh_wrong(), 2u);
}

TEST(RayDiff, EndToEndOnSphere) {
  Scene s;
  s.add_mesh(generate_sphere(2000));
  BackendOptions o;
  o.threads = 2;
  run_with_threads(2, [&] {
    auto bvh = make_intersector("bvh", o);
    auto embree = make_intersector("embree", o);
    bvh->build(s);
    embree->build(s);
    for (RayKind k : {RayKind::kRandom, RayKind::kEdgeProbe}) {
      const std::vector<Ray> rays = make_rays(s, k, 3000, 7, embree.get());
      const RayDiffResult r = run_ray_diff(s, rays, *bvh, *embree, false);
      EXPECT_EQ(r.rays, 3000u);
      EXPECT_EQ(r.agree + r.ties + r.mismatches, r.rays);
      EXPECT_EQ(r.bvh_wrong(), 0u) << to_string(k);
      EXPECT_GT(r.agree, 0u);
      EXPECT_LE(r.max_rel_t_error, 1e-5);
      const RayDiffResult ro = run_ray_diff(s, rays, *bvh, *embree, true);
      EXPECT_EQ(ro.bvh_wrong(), 0u) << to_string(k) << " occluded";
    }
  });
}

}  // namespace
}  // namespace hprt
