// Embree reference backend: hit records, double-sidedness, intervals,
// occlusion, IDs, invalid rays, thread-count independence, option variants.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "backends/embree_backend.h"
#include "core/error.h"
#include "core/parallel.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

using test::kInf;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

TriangleMesh one_triangle(Vec3f offset = Vec3f(0.0f)) {
  TriangleMesh m;
  m.name = "tri";
  m.positions = {Vec3f(0, 0, 0) + offset, Vec3f(1, 0, 0) + offset, Vec3f(0, 1, 0) + offset};
  m.triangles = {Vec3u{{0, 1, 2}}};
  return m;
}

Ray make_ray(Vec3f org, Vec3f dir, float tnear = 0.0f, float tfar = kInf) {
  Ray r;
  r.org = org;
  r.dir = dir;
  r.tnear = tnear;
  r.tfar = tfar;
  return r;
}

std::unique_ptr<Intersector> built(const Scene& scene, BackendOptions o = {}) {
  o.backend = "embree";
  auto b = make_embree_intersector(o);
  b->build(scene);
  return b;
}

Hit trace_one(const Intersector& b, const Ray& r) {
  Hit h;
  b.intersect(std::span<const Ray>(&r, 1), std::span<Hit>(&h, 1));
  return h;
}

bool occluded_one(const Intersector& b, const Ray& r) {
  uint8_t o = 7;
  b.occluded(std::span<const Ray>(&r, 1), std::span<uint8_t>(&o, 1));
  EXPECT_TRUE(o == 0 || o == 1);
  return o == 1;
}

TEST(EmbreeBackend, FrontHitRecord) {
  Scene s;
  s.add_mesh(one_triangle());
  auto b = built(s);
  const Hit h = trace_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -1}));
  ASSERT_TRUE(h.hit());
  EXPECT_FLOAT_EQ(h.t, 1.0f);
  EXPECT_FLOAT_EQ(h.u, 0.25f);
  EXPECT_FLOAT_EQ(h.v, 0.25f);
  EXPECT_EQ(h.prim_id, 0u);
  EXPECT_EQ(h.geom_id, 0u);
  EXPECT_EQ(b->info().name, "embree/medium");
  EXPECT_GT(b->info().memory_bytes, 0u);
}

TEST(EmbreeBackend, BackSideHitsDoubleSided) {
  Scene s;
  s.add_mesh(one_triangle());
  auto b = built(s);
  const Hit h = trace_one(*b, make_ray({0.5f, 0.25f, -2.0f}, {0, 0, 1}));
  ASSERT_TRUE(h.hit());
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_FLOAT_EQ(h.u, 0.5f);
  EXPECT_FLOAT_EQ(h.v, 0.25f);
}

TEST(EmbreeBackend, MissesAndIntervals) {
  Scene s;
  s.add_mesh(one_triangle());
  auto b = built(s);
  const Hit outside = trace_one(*b, make_ray({0.75f, 0.75f, 1.0f}, {0, 0, -1}));
  EXPECT_FALSE(outside.hit());
  EXPECT_EQ(outside.t, kInf);
  EXPECT_EQ(outside.geom_id, kInvalidId);
  EXPECT_EQ(outside.u, 0.0f);
  EXPECT_FALSE(trace_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -1}, 0.0f, 0.9f)).hit());
  EXPECT_FALSE(trace_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -1}, 1.1f, kInf)).hit());
  EXPECT_FALSE(trace_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, 1})).hit());  // away
  // Unnormalised direction: t is in units of dir.
  const Hit scaled = trace_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -4}));
  ASSERT_TRUE(scaled.hit());
  EXPECT_FLOAT_EQ(scaled.t, 0.25f);
}

TEST(EmbreeBackend, Occlusion) {
  Scene s;
  s.add_mesh(one_triangle());
  auto b = built(s);
  EXPECT_TRUE(occluded_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -1})));
  EXPECT_FALSE(occluded_one(*b, make_ray({0.75f, 0.75f, 1.0f}, {0, 0, -1})));
  EXPECT_FALSE(occluded_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -1}, 0.0f, 0.5f)));
  EXPECT_FALSE(occluded_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {kNaN, 0, -1})));
}

TEST(EmbreeBackend, GeomIdIsMeshIndexAndClosestWins) {
  Scene s;
  s.add_mesh(one_triangle(Vec3f(0, 0, 0)));
  s.add_mesh(one_triangle(Vec3f(0, 0, 0.5f)));
  auto b = built(s);
  const Hit from_above = trace_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -1}));
  EXPECT_EQ(from_above.geom_id, 1u);
  EXPECT_FLOAT_EQ(from_above.t, 0.5f);
  const Hit from_below = trace_one(*b, make_ray({0.25f, 0.25f, -1.0f}, {0, 0, 1}));
  EXPECT_EQ(from_below.geom_id, 0u);
  EXPECT_FLOAT_EQ(from_below.t, 1.0f);
}

TEST(EmbreeBackend, PrimIdIsInputOrder) {
  // A row of 50 unit triangles along x in shuffled order: triangle i covers
  // x in [k, k+1) where k = order[i].
  TriangleMesh m;
  m.name = "row";
  std::vector<uint32_t> order(50);
  for (uint32_t i = 0; i < 50; ++i) order[i] = (i * 17) % 50;
  for (uint32_t i = 0; i < 50; ++i) {
    const float x = float(order[i]);
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.push_back({x, 0, 0});
    m.positions.push_back({x + 1, 0, 0});
    m.positions.push_back({x, 1, 0});
    m.triangles.push_back(Vec3u{{base, base + 1, base + 2}});
  }
  Scene s;
  s.add_mesh(m);
  auto b = built(s);
  for (uint32_t i = 0; i < 50; ++i) {
    const Hit h = trace_one(*b, make_ray({float(order[i]) + 0.2f, 0.3f, 1.0f}, {0, 0, -1}));
    ASSERT_TRUE(h.hit());
    EXPECT_EQ(h.prim_id, i);
  }
}

TEST(EmbreeBackend, InvalidRaysMiss) {
  // NaN, infinite or huge (> Embree's FLT_LARGE) components, zero
  // direction, tnear < 0 and empty or NaN intervals: all miss.
  Scene s;
  s.add_mesh(one_triangle());
  auto b = built(s);
  const Vec3f o{0.25f, 0.25f, 1.0f}, d{0, 0, -1};
  const std::vector<Ray> bad = {
      make_ray({kNaN, 0.25f, 1.0f}, d),
      make_ray(o, {0, kNaN, -1}),
      make_ray(o, {0, 0, 0}),
      make_ray(o, {-0.0f, -0.0f, -0.0f}),
      make_ray(o, {0, 0, -kInf}),
      make_ray(o, d, kNaN, kInf),
      make_ray(o, d, 0.0f, kNaN),
      make_ray(o, d, 2.0f, 1.0f),
      make_ray({0.25f, 0.25f, kInf}, d),
      make_ray(o, d, -1.0f, kInf),
      make_ray({0.25f, 0.25f, 2e18f}, d),
      make_ray(o, {0, 0, -2e18f}),
  };
  std::vector<Hit> hits(bad.size());
  b->intersect(bad, hits);
  for (size_t i = 0; i < hits.size(); ++i) {
    EXPECT_FALSE(hits[i].hit()) << "ray " << i;
    EXPECT_EQ(hits[i].t, kInf) << "ray " << i;
  }
  std::vector<uint8_t> occ(bad.size(), 9);
  b->occluded(bad, occ);
  for (size_t i = 0; i < occ.size(); ++i) EXPECT_EQ(occ[i], 0) << "ray " << i;
}

TEST(EmbreeBackend, BadIndexIsInputError) {
  Scene s;
  TriangleMesh m = one_triangle();
  m.name = "broken.ply";
  m.triangles.push_back(Vec3u{{0, 1, 3}});
  s.add_mesh(m);
  auto b = make_embree_intersector(BackendOptions{});
  try {
    b->build(s);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "broken.ply: triangle 1 references vertex 3 of 3");
  }
}

TEST(EmbreeBackend, UnpaddedMeshIsCopiedNotOverread) {
  Scene s;
  s.meshes.push_back(one_triangle());  // no add_mesh: maybe no spare capacity
  s.meshes[0].positions.shrink_to_fit();
  ASSERT_FALSE(s.meshes[0].padded_for_embree());
  auto b = built(s);
  EXPECT_TRUE(trace_one(*b, make_ray({0.25f, 0.25f, 1.0f}, {0, 0, -1})).hit());
}

Scene random_soup(size_t triangles, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f), small(-0.1f, 0.1f);
  TriangleMesh m;
  m.name = "soup";
  for (size_t i = 0; i < triangles; ++i) {
    const Vec3f c(pos(rng), pos(rng), pos(rng));
    for (int k = 0; k < 3; ++k)
      m.positions.push_back(c + Vec3f(small(rng), small(rng), small(rng)));
    const uint32_t b = uint32_t(3 * i);
    m.triangles.push_back(Vec3u{{b, b + 1, b + 2}});
  }
  Scene s;
  s.add_mesh(m);
  return s;
}

std::vector<Ray> random_rays(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.5f, 1.5f), dir(-1.0f, 1.0f);
  std::vector<Ray> rays(n);
  for (Ray& r : rays) r = make_ray({pos(rng), pos(rng), pos(rng)}, {dir(rng), dir(rng), dir(rng)});
  return rays;
}

std::vector<Hit> trace_with(const Scene& s, const std::vector<Ray>& rays, BackendOptions o) {
  return run_with_threads(o.threads, [&] {
    auto b = built(s, o);
    std::vector<Hit> hits(rays.size());
    b->intersect(rays, hits);
    return hits;
  });
}

void expect_same_hits(const std::vector<Hit>& a, const std::vector<Hit>& b, bool exact) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].prim_id, b[i].prim_id) << "ray " << i;
    if (exact) {
      EXPECT_EQ(a[i].t, b[i].t) << "ray " << i;
      EXPECT_EQ(a[i].u, b[i].u) << "ray " << i;
      EXPECT_EQ(a[i].v, b[i].v) << "ray " << i;
    } else if (a[i].hit()) {
      EXPECT_NEAR(a[i].t, b[i].t, 1e-5f * a[i].t) << "ray " << i;
    }
  }
}

TEST(EmbreeBackend, ThreadCountDoesNotChangeHits) {
  const Scene s = random_soup(2000, 1);
  const std::vector<Ray> rays = random_rays(1000, 2);
  BackendOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const std::vector<Hit> a = trace_with(s, rays, one);
  const std::vector<Hit> b = trace_with(s, rays, two);
  size_t hits = 0;
  for (const Hit& h : a) hits += h.hit();
  EXPECT_GT(hits, 100u);  // the test means something only if many rays hit
  expect_same_hits(a, b, true);
}

TEST(EmbreeBackend, CoherentPacketsMatchSingleRays) {
  // Camera-like rays (one origin, narrow cone) are traced as 16-ray packets
  // in a batch; the same rays one at a time take the single-ray path. Both
  // must give the same bits, for closest hit and occlusion.
  const Scene s = random_soup(3000, 5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> spread(-0.3f, 0.3f);
  std::vector<Ray> rays(4000);
  for (Ray& r : rays) r = make_ray({0.0f, 0.0f, 3.0f}, {spread(rng), spread(rng), -1.0f});
  rays[37].dir.x = kNaN;  // an invalid ray inside a group: that group goes ray by ray
  for (int threads : {1, 2}) {
    BackendOptions o;
    o.threads = threads;
    run_with_threads(threads, [&] {
      auto b = built(s, o);
      std::vector<Hit> batch(rays.size());
      b->intersect(rays, batch);
      std::vector<uint8_t> occ(rays.size());
      b->occluded(rays, occ);
      size_t hits = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        const Hit one = trace_one(*b, rays[i]);
        hits += one.hit();
        EXPECT_EQ(batch[i].prim_id, one.prim_id) << "ray " << i;
        EXPECT_EQ(batch[i].t, one.t) << "ray " << i;
        EXPECT_EQ(batch[i].u, one.u) << "ray " << i;
        EXPECT_EQ(batch[i].v, one.v) << "ray " << i;
        EXPECT_EQ(occ[i], occluded_one(*b, rays[i]) ? 1 : 0) << "ray " << i;
        EXPECT_EQ(occ[i], one.hit() ? 1 : 0) << "ray " << i;
      }
      EXPECT_FALSE(batch[37].hit());
      EXPECT_GT(hits, 1000u);
    });
  }
}

TEST(EmbreeBackend, QualitiesAndRobustAgree) {
  const Scene s = random_soup(500, 3);
  const std::vector<Ray> rays = random_rays(1000, 4);
  const std::vector<Hit> ref = trace_with(s, rays, BackendOptions{});
  for (const char* q : {"low", "medium", "high", "refit"})
    for (bool robust : {false, true}) {
      BackendOptions o;
      o.embree_quality = q;
      o.embree_robust = robust;
      SCOPED_TRACE(std::string(q) + (robust ? "/robust" : ""));
      expect_same_hits(ref, trace_with(s, rays, o), false);
    }
  BackendOptions bad;
  bad.embree_quality = "ultra";
  EXPECT_THROW(make_embree_intersector(bad), InputError);
}

TEST(EmbreeBackend, UpdateFollowsMovedVertices) {
  for (const char* q : {"medium", "refit"}) {
    SCOPED_TRACE(q);
    Scene s;
    s.add_mesh(one_triangle());
    BackendOptions o;
    o.embree_quality = q;
    auto b = built(s, o);
    const Ray r = make_ray({0.25f, 0.25f, 5.0f}, {0, 0, -1});
    EXPECT_FLOAT_EQ(trace_one(*b, r).t, 5.0f);
    for (Vec3f& p : s.meshes[0].positions) p.z += 2.0f;  // in place
    b->update(s);
    EXPECT_FLOAT_EQ(trace_one(*b, r).t, 3.0f);
    EXPECT_EQ(b->info().rebuilt, std::string(q) != "refit");
    // A different topology is a rebuild.
    s.meshes.push_back(one_triangle(Vec3f(0, 0, 4.0f)));
    s.meshes.back().pad_for_embree();
    b->update(s);
    const Hit h = trace_one(*b, r);
    EXPECT_EQ(h.geom_id, 1u);
    EXPECT_FLOAT_EQ(h.t, 1.0f);
    EXPECT_TRUE(b->info().rebuilt);
  }
}

TEST(EmbreeBackend, EmptySceneMisses) {
  Scene s;
  auto b = built(s);
  EXPECT_FALSE(trace_one(*b, make_ray({0, 0, 1}, {0, 0, -1})).hit());
}

}  // namespace
}  // namespace hprt
