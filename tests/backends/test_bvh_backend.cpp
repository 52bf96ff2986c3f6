// The bvh backend through the Intersector interface, against the Embree
// backend on the same rays: same primitive (or a tie at the same t) and t
// within 1e-5 relative, for both triangle tests and several builders;
// results identical for 1 and 2 threads; invalid rays and empty scenes miss.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "backends/intersector.h"
#include "bvh/memory/huge_buffer.h"
#include "core/parallel.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

struct Answers {
  std::vector<Hit> hits;
  std::vector<uint8_t> occluded;
  BuildInfo info;
};

Answers ask(const Intersector& isect, const std::vector<Ray>& rays) {
  Answers a;
  a.hits.resize(rays.size());
  a.occluded.resize(rays.size());
  isect.intersect(rays, a.hits);
  isect.occluded(rays, a.occluded);
  a.info = isect.info();
  return a;
}

Answers run(const Scene& scene, const std::vector<Ray>& rays, BackendOptions o,
            const std::string& backend, int threads) {
  o.threads = threads;
  return run_with_threads(threads, [&] {
    auto isect = make_intersector(backend, o);
    isect->build(scene);
    return ask(*isect, rays);
  });
}

bool close_rel(float a, float b) {
  return std::fabs(a - b) <= 1e-5f * std::max(std::fabs(a), std::fabs(b));
}

void compare_with_embree(const Scene& scene, const std::vector<Ray>& rays, TriangleTestKind kind,
                         BuilderKind builder, BvhLayout layout = BvhLayout::kBvh8) {
  SCOPED_TRACE(to_string(layout));
  BackendOptions o;
  o.triangle_test = kind;
  o.build.builder = builder;
  o.layout = layout;
  const Answers bvh = run(scene, rays, o, "bvh", 2);
  const Answers emb = run(scene, rays, o, "embree", 2);
  size_t hits = 0, ties = 0, mismatches = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Hit& a = bvh.hits[i];
    const Hit& b = emb.hits[i];
    if (a.hit() != b.hit()) {
      ++mismatches;
      continue;
    }
    EXPECT_EQ(bvh.occluded[i], a.hit() ? 1 : 0) << i;
    if (!a.hit()) continue;
    ++hits;
    EXPECT_EQ(a.geom_id, b.geom_id);
    if (!close_rel(a.t, b.t)) {
      ++mismatches;
      continue;
    }
    if (a.prim_id != b.prim_id) {
      ++ties;
    } else {
      EXPECT_NEAR(a.u, b.u, 1e-4f);
      EXPECT_NEAR(a.v, b.v, 1e-4f);
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_GT(hits, rays.size() / 10);
  EXPECT_LE(ties, hits / 100 + 5);
}

TEST(BvhBackend, AgreesWithEmbreeOnSoup) {
  const Scene scene = test::scene_of({test::random_soup(20000, 5, 0.03f)});
  const auto rays = test::random_rays(scene.bounds(), 10000, 17);
  compare_with_embree(scene, rays, TriangleTestKind::kWatertight, BuilderKind::kParallel);
  compare_with_embree(scene, rays, TriangleTestKind::kMoller, BuilderKind::kBinned);
  compare_with_embree(scene, rays, TriangleTestKind::kWatertight, BuilderKind::kBinned,
                      BvhLayout::kBvh2);
  compare_with_embree(scene, rays, TriangleTestKind::kMoller, BuilderKind::kParallel,
                      BvhLayout::kBvh4);
}

TEST(BvhBackend, AgreesWithEmbreeOnClosedSphere) {
  const Scene scene = test::scene_of({test::icosphere(5), test::grid(30, 30)});
  auto rays = test::random_rays(scene.bounds(), 10000, 23);
  const auto more = test::coherent_rays(scene.bounds(), 60, 40);
  rays.insert(rays.end(), more.begin(), more.end());
  compare_with_embree(scene, rays, TriangleTestKind::kWatertight, BuilderKind::kParallel);
  compare_with_embree(scene, rays, TriangleTestKind::kMoller, BuilderKind::kSweep);
  compare_with_embree(scene, rays, TriangleTestKind::kWatertight, BuilderKind::kSweep,
                      BvhLayout::kBvh4);
  compare_with_embree(scene, rays, TriangleTestKind::kMoller, BuilderKind::kParallel,
                      BvhLayout::kBvh2);
}

// The layout changes how the tree is stored, never what a ray hits: all three
// give the same answers bit for bit, for both triangle tests, after a build
// and after a refit of the deformed scene.
TEST(BvhBackend, LayoutsAnswerIdentically) {
  const Scene scene = test::scene_of({test::random_soup(20000, 9, 0.03f), test::icosphere(4)});
  Scene moved = scene;
  for (TriangleMesh& m : moved.meshes)
    for (Vec3f& p : m.positions) p = p + Vec3f{0.1f * std::sin(7 * p.y), 0.0f, 0.05f * p.x};
  auto rays = test::random_rays(scene.bounds(), 8000, 31);
  const auto more = test::coherent_rays(scene.bounds(), 40, 40);
  rays.insert(rays.end(), more.begin(), more.end());
  for (TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller}) {
    std::vector<Answers> built, refitted;
    for (BvhLayout layout : {BvhLayout::kBvh2, BvhLayout::kBvh4, BvhLayout::kBvh8}) {
      BackendOptions o;
      o.triangle_test = kind;
      o.layout = layout;
      o.update = UpdateStrategy::kRefit;
      run_with_threads(2, [&] {
        auto isect = make_intersector("bvh", o);
        isect->build(scene);
        built.push_back(ask(*isect, rays));
        isect->update(moved);
        refitted.push_back(ask(*isect, rays));
        return 0;
      });
    }
    const std::string name = "bvh/parallel/" + std::string(to_string(kind));
    EXPECT_EQ(built[0].info.name, name + "/bvh2");
    EXPECT_EQ(built[1].info.name, name + "/bvh4");
    EXPECT_EQ(built[2].info.name, name);
    for (const std::vector<Answers>* answers : {&built, &refitted}) {
      const std::vector<Answers>& a = *answers;
      for (size_t l = 1; l < a.size(); ++l) {
        EXPECT_EQ(a[l].info.stats.tree_hash, a[0].info.stats.tree_hash);
        EXPECT_NEAR(a[l].info.stats.sah_cost, a[0].info.stats.sah_cost,
                    1e-9 * a[0].info.stats.sah_cost);
        size_t differ = 0, hits = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
          const Hit& x = a[0].hits[i];
          const Hit& y = a[l].hits[i];
          hits += x.hit();
          differ += x.t != y.t || x.prim_id != y.prim_id || x.geom_id != y.geom_id || x.u != y.u ||
                    x.v != y.v || a[0].occluded[i] != a[l].occluded[i];
        }
        EXPECT_EQ(differ, 0u) << to_string(kind) << " layout " << l;
        EXPECT_GT(hits, rays.size() / 10);
      }
    }
    EXPECT_FALSE(refitted[2].info.rebuilt);
  }
}

TEST(BvhBackend, OneAndTwoThreadsIdentical) {
  const Scene scene = test::scene_of({test::random_soup(30000, 8, 0.03f)});
  const auto rays = test::random_rays(scene.bounds(), 10000, 29);
  for (TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller}) {
    BackendOptions o;
    o.triangle_test = kind;
    const Answers a = run(scene, rays, o, "bvh", 1);
    const Answers b = run(scene, rays, o, "bvh", 2);
    EXPECT_EQ(a.info.stats.tree_hash, b.info.stats.tree_hash);
    ASSERT_EQ(a.hits.size(), b.hits.size());
    for (size_t i = 0; i < rays.size(); ++i) {
      EXPECT_EQ(a.hits[i].t, b.hits[i].t);
      EXPECT_EQ(a.hits[i].prim_id, b.hits[i].prim_id);
      EXPECT_EQ(a.hits[i].u, b.hits[i].u);
      EXPECT_EQ(a.occluded[i], b.occluded[i]);
    }
  }
}

// update()'s rebuild (with full_stats_on_update, the tree statistics beside
// the flattening; build() after it): same statistics, hash and answers as a
// fresh build of the moved scene, for both SAH and Morton trees, at 2
// threads. Without the option it reports the same SAH cost and counts.
TEST(BvhBackend, RebuildingUpdateEqualsAFreshBuild) {
  const Scene scene = test::scene_of({test::random_soup(6000, 12, 0.03f), test::icosphere(3)});
  Scene moved = scene;
  for (TriangleMesh& m : moved.meshes)
    for (Vec3f& p : m.positions) p = p + Vec3f{0.2f * std::sin(5 * p.y), 0.1f * p.z, 0.0f};
  const auto rays = test::random_rays(moved.bounds(), 2000, 33);
  for (BuilderKind builder : {BuilderKind::kParallel, BuilderKind::kMorton}) {
    BackendOptions o;
    o.build.builder = builder;
    o.build.parallel_cutoff = 256;  // parallel tasks even on this small scene
    o.update = UpdateStrategy::kRebuild;
    run_with_threads(2, [&] {
      BackendOptions light = o;
      o.full_stats_on_update = true;
      auto updated = make_intersector("bvh", o);
      updated->build(scene);
      updated->update(moved);
      auto fresh = make_intersector("bvh", o);
      fresh->build(moved);
      const Answers a = ask(*updated, rays), b = ask(*fresh, rays);
      auto quick = make_intersector("bvh", light);
      quick->build(scene);
      quick->update(moved);
      const TreeStats q = quick->info().stats;
      EXPECT_NEAR(q.sah_cost, b.info.stats.sah_cost, 1e-9 * b.info.stats.sah_cost);
      EXPECT_EQ(q.nodes, b.info.stats.nodes);
      EXPECT_EQ(q.triangles, b.info.stats.triangles);
      EXPECT_EQ(q.tree_hash, 0u);
      EXPECT_EQ(q.depth, 0);
      EXPECT_TRUE(a.info.rebuilt);
      EXPECT_EQ(a.info.stats.tree_hash, b.info.stats.tree_hash) << to_string(builder);
      EXPECT_EQ(a.info.stats.sah_cost, b.info.stats.sah_cost);
      EXPECT_EQ(a.info.stats.nodes, b.info.stats.nodes);
      EXPECT_EQ(a.info.stats.depth, b.info.stats.depth);
      EXPECT_EQ(a.info.memory_bytes, b.info.memory_bytes);
      for (size_t i = 0; i < rays.size(); ++i) {
        EXPECT_EQ(a.hits[i].t, b.hits[i].t) << i;
        EXPECT_EQ(a.hits[i].prim_id, b.hits[i].prim_id) << i;
        EXPECT_EQ(a.occluded[i], b.occluded[i]) << i;
      }
      return 0;
    });
  }
}

// An animated scene will be updated: its build() keeps the freed arrays for
// the first rebuild already (no fresh pages on the first frame), and the
// rebuild over them answers as a fresh build.
TEST(BvhBackend, AnimatedSceneKeepsItsBuildArrays) {
  Scene scene = test::scene_of({test::random_soup(100000, 4, 0.01f)});
  DeformerSpec wave;
  wave.mesh = 0;
  wave.kind = "wave";
  scene.animation.deformers.push_back(wave);
  ASSERT_TRUE(scene.animation.animated());
  ASSERT_EQ(huge_buffer_cache_bytes(), 0u);
  BackendOptions o;
  o.build.builder = BuilderKind::kMorton;
  o.update = UpdateStrategy::kRebuild;
  o.full_stats_on_update = true;
  {
    auto isect = make_intersector("bvh", o);
    isect->build(scene);
    EXPECT_GT(huge_buffer_cache_bytes(), 0u);
    const uint64_t built = isect->info().stats.tree_hash;
    isect->update(scene);
    EXPECT_EQ(isect->info().stats.tree_hash, built);
  }
  EXPECT_EQ(huge_buffer_cache_bytes(), 0u);
}

// The refit index is made with the tree only for an animated scene; after a
// one-off build the first refit makes it. Both paths refit to the same tree
// and answers, also after an adaptive rebuild in between and for every
// layout and triangle test.
TEST(BvhBackend, RefitAfterAOneOffBuildEqualsRefitOfAnAnimatedBuild) {
  Scene still = test::scene_of({test::random_soup(20000, 6, 0.02f), test::icosphere(3)});
  Scene animated = still;
  DeformerSpec wave;
  wave.mesh = 0;
  wave.kind = "wave";
  animated.animation.deformers.push_back(wave);
  std::vector<Scene> frames;
  for (float a : {0.05f, 0.1f, 3.0f, 3.05f}) {  // the jump to 3.0 forces an adaptive rebuild
    Scene f = still;
    for (TriangleMesh& m : f.meshes)
      for (Vec3f& p : m.positions) p = p + Vec3f{a * std::sin(7 * p.y), 0.0f, 0.05f * a * p.x};
    frames.push_back(std::move(f));
  }
  const auto rays = test::random_rays(still.bounds(), 3000, 37);
  for (TriangleTestKind kind : {TriangleTestKind::kWatertight, TriangleTestKind::kMoller})
    for (BvhLayout layout : {BvhLayout::kBvh2, BvhLayout::kBvh8}) {
      SCOPED_TRACE(std::string(to_string(kind)) + " " + std::string(to_string(layout)));
      BackendOptions o;
      o.triangle_test = kind;
      o.layout = layout;
      o.update = UpdateStrategy::kAdaptive;
      o.full_stats_on_update = true;
      run_with_threads(2, [&] {
        auto one_off = make_intersector("bvh", o);
        auto anim = make_intersector("bvh", o);
        one_off->build(still);
        anim->build(animated);
        bool rebuilt = false, refitted = false;
        for (const Scene& f : frames) {
          one_off->update(f);
          anim->update(f);
          const Answers a = ask(*one_off, rays), b = ask(*anim, rays);
          EXPECT_EQ(a.info.rebuilt, b.info.rebuilt);
          rebuilt = rebuilt || a.info.rebuilt;
          refitted = refitted || !a.info.rebuilt;
          EXPECT_EQ(a.info.stats.sah_cost, b.info.stats.sah_cost);
          for (size_t i = 0; i < rays.size(); ++i) {
            EXPECT_EQ(a.hits[i].t, b.hits[i].t) << i;
            EXPECT_EQ(a.hits[i].prim_id, b.hits[i].prim_id) << i;
            EXPECT_EQ(a.occluded[i], b.occluded[i]) << i;
          }
        }
        EXPECT_TRUE(rebuilt);
        EXPECT_TRUE(refitted);
        return 0;
      });
    }
}

// The freed build arrays are cached (for the next rebuild) only while a
// backend that was updated lives; rebuilds over reused arrays answer as a
// fresh build.
TEST(BvhBackend, KeepsBuildArraysOnlyForUpdatesAndRebuildsOverThemExactly) {
  // Large enough for arrays of at least 2 MiB (the prim boxes: 2.4 MB), the
  // sizes the cache takes.
  const Scene scene = test::scene_of({test::random_soup(100000, 4, 0.01f)});
  Scene moved = scene;
  for (Vec3f& p : moved.meshes[0].positions) p = p + Vec3f{0.1f * std::sin(7 * p.y), 0.0f, 0.0f};
  const auto rays = test::random_rays(scene.bounds(), 2000, 35);
  ASSERT_EQ(huge_buffer_cache_bytes(), 0u);
  for (BuilderKind builder : {BuilderKind::kParallel, BuilderKind::kMorton})
    for (BvhLayout layout : {BvhLayout::kBvh2, BvhLayout::kBvh4, BvhLayout::kBvh8}) {
      SCOPED_TRACE(std::string(to_string(builder)) + " " + std::string(to_string(layout)));
      BackendOptions o;
      o.build.builder = builder;
      o.layout = layout;
      o.update = UpdateStrategy::kRebuild;
      o.full_stats_on_update = true;  // the hash below
      {
        auto isect = make_intersector("bvh", o);
        isect->build(scene);
        EXPECT_EQ(huge_buffer_cache_bytes(), 0u) << "a static build keeps nothing";
        isect->update(moved);
        isect->update(scene);  // rebuilt over the arrays of the first update
        EXPECT_GT(huge_buffer_cache_bytes(), 0u);
        auto fresh = make_intersector("bvh", o);
        fresh->build(scene);
        const Answers a = ask(*isect, rays), b = ask(*fresh, rays);
        EXPECT_EQ(a.info.stats.tree_hash, b.info.stats.tree_hash) << to_string(builder);
        for (size_t i = 0; i < rays.size(); ++i) {
          EXPECT_EQ(a.hits[i].t, b.hits[i].t) << i;
          EXPECT_EQ(a.hits[i].prim_id, b.hits[i].prim_id) << i;
          EXPECT_EQ(a.occluded[i], b.occluded[i]) << i;
        }
      }
      EXPECT_EQ(huge_buffer_cache_bytes(), 0u) << "emptied with the last backend that kept it";
    }
}

TEST(BvhBackend, InfoReportsTheBuild) {
  const Scene scene = test::scene_of({test::with_invalid_triangles(), test::random_soup(1000, 1)});
  BackendOptions o;
  o.build.builder = BuilderKind::kBinned;
  o.triangle_test = TriangleTestKind::kMoller;
  const Answers a = run(scene, {}, o, "bvh", 1);
  EXPECT_EQ(a.info.name, "bvh/binned/mt");
  EXPECT_TRUE(a.info.has_tree_stats);
  EXPECT_EQ(a.info.stats.triangles, 1006u);
  EXPECT_EQ(a.info.stats.invalid_triangles, 5u);
  // At least the Möller-Trumbore triangle arrays (edges and ids), plus nodes.
  EXPECT_GT(a.info.memory_bytes, 1006u * (sizeof(TriangleEdges) + sizeof(PrimRef)));
  EXPECT_GE(a.info.build_ms, 0.0);
}

TEST(BvhBackend, EmptySceneAndInvalidRaysMiss) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<Ray> rays(6);
  for (Ray& r : rays) {
    r.org = {0.5f, 0.5f, 2.0f};
    r.dir = {0, 0, -1};
  }
  rays[0].dir = {nan, 0, -1};
  rays[1].org = {nan, 0.5f, 2.0f};
  rays[2].dir = {0, 0, 0};
  rays[3].dir = {inf, 0, -1};
  rays[4].tnear = 3.0f;
  rays[4].tfar = 1.0f;
  rays[5].tfar = nan;
  for (const Scene& scene : {test::scene_of({}), test::scene_of({test::grid(4, 4)})}) {
    const Answers a = run(scene, rays, BackendOptions{}, "bvh", 2);
    for (size_t i = 0; i < rays.size(); ++i) {
      EXPECT_FALSE(a.hits[i].hit()) << i;
      EXPECT_EQ(a.hits[i].t, inf);
      EXPECT_EQ(a.occluded[i], 0) << i;
    }
  }
}

}  // namespace
}  // namespace hprt
