// Update strategies of the bvh backend (rebuild, refit, adaptive, auto) over every
// deformer: after each frame the bvh answers agree with a fresh Embree build
// on primary, shadow and random rays (the exact arbiter settles disputes;
// bvh is never wrong); adaptive rebuilds during explode and not during a
// gentle wave; auto rebuilds an exploding mesh that is queried heavily, with
// the Morton builder, and only refits a mesh that is not queried; a change
// of the valid-triangle set forces a rebuild; Embree's
// dynamic update (refit and low quality) answers as a fresh Embree build.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "anim/scene_animator.h"
#include "backends/intersector.h"
#include "core/parallel.h"
#include "io/scene/scene_reader.h"
#include "meshgen/mesh_generators.h"
#include "validators/ray_diff.h"
#include "validators/ray_sets.h"

namespace hprt {
namespace {

constexpr int kStrategyThreads = 2;
constexpr int kFrames = 4;  // frame 0 = the build, then 3 updates
constexpr size_t kStrategyRays = 600;

// A ~20k-triangle unit sphere with one deformer; fps 8, so frames 1..3 are
// t = 0.125 .. 0.375 s.
Scene deformed_sphere(const DeformerSpec& d) {
  Scene s;
  s.add_mesh(generate_sphere(20000));
  s.camera = framing_camera(s.bounds(), s.camera);
  s.camera.width = 64;
  s.camera.height = 48;
  s.lights = {head_light(s.camera)};
  s.animation.frames = kFrames;
  s.animation.fps = 8.0f;
  s.animation.deformers = {d};
  return s;
}

DeformerSpec spec(const std::string& kind) {
  DeformerSpec d;
  d.kind = kind;
  if (kind == "wave") {  // gentle: 2% of the radius
    d.amplitude = 0.02f;
    d.wavelength = 0.5f;
    d.speed = 1.0f;
  } else if (kind == "pulse") {
    d.amplitude = 0.2f;
    d.speed = 1.0f;
  } else if (kind == "explode") {  // triangles fly 0.06..0.56 units by frame 3
    d.amplitude = 1.0f;
    d.speed = 1.0f;
  } else {  // twist, bend
    d.angle_deg = 180.0f;
    d.axis = 1;
  }
  return d;
}

std::unique_ptr<Intersector> bvh_backend(UpdateStrategy u) {
  BackendOptions o;
  o.threads = kStrategyThreads;
  o.update = u;
  return make_intersector("bvh", o);
}

std::unique_ptr<Intersector> embree_backend(const std::string& quality) {
  BackendOptions o;
  o.threads = kStrategyThreads;
  o.embree_quality = quality;
  return make_intersector("embree", o);
}

const char* name(UpdateStrategy u) {
  return u == UpdateStrategy::kRebuild    ? "rebuild"
         : u == UpdateStrategy::kRefit    ? "refit"
         : u == UpdateStrategy::kAdaptive ? "adaptive"
                                          : "auto";
}

struct DeformRun {
  std::vector<bool> adaptive_rebuilt;  // per update, adaptive strategy
};

// Animates frames 1..kFrames-1 and checks every backend after each frame.
DeformRun check_deformer(const std::string& kind) {
  DeformRun run;
  Scene scene = deformed_sphere(spec(kind));
  run_with_threads(kStrategyThreads, [&] {
    const SceneAnimator animator(scene);
    animator.apply(0, scene);
    const UpdateStrategy strategies[] = {UpdateStrategy::kRebuild, UpdateStrategy::kRefit,
                                         UpdateStrategy::kAdaptive, UpdateStrategy::kAuto};
    std::vector<std::unique_ptr<Intersector>> bvhs;
    for (UpdateStrategy u : strategies) {
      bvhs.push_back(bvh_backend(u));
      bvhs.back()->build(scene);
    }
    // Refit with Möller–Trumbore: the refit re-gathers the edges array it reads.
    BackendOptions mt;
    mt.threads = kStrategyThreads;
    mt.update = UpdateStrategy::kRefit;
    mt.triangle_test = TriangleTestKind::kMoller;
    auto bvh_mt = make_intersector("bvh", mt);
    bvh_mt->build(scene);
    // Adaptive over the Morton builder's trees.
    BackendOptions morton;
    morton.threads = kStrategyThreads;
    morton.build.builder = BuilderKind::kMorton;
    morton.update = UpdateStrategy::kAdaptive;
    auto bvh_morton = make_intersector("bvh", morton);
    bvh_morton->build(scene);
    auto embree_refit = embree_backend("refit"), embree_low = embree_backend("low");
    embree_refit->build(scene);
    embree_low->build(scene);
    for (int frame = 1; frame < kFrames; ++frame) {
      animator.apply(frame, scene);
      auto fresh = embree_backend("medium");
      fresh->build(scene);
      std::vector<Ray> rays;
      uint64_t seed = 100 + frame;
      for (RayKind k : {RayKind::kPrimary, RayKind::kShadow, RayKind::kRandom}) {
        const std::vector<Ray> r = make_rays(scene, k, kStrategyRays, seed++, fresh.get());
        rays.insert(rays.end(), r.begin(), r.end());
      }
      for (size_t s = 0; s < bvhs.size(); ++s) {
        bvhs[s]->update(scene);
        const BuildInfo info = bvhs[s]->info();
        if (strategies[s] == UpdateStrategy::kAdaptive) {
          run.adaptive_rebuilt.push_back(info.rebuilt);
        } else if (strategies[s] != UpdateStrategy::kAuto) {  // auto: from measured times
          EXPECT_EQ(info.rebuilt, strategies[s] == UpdateStrategy::kRebuild);
        }
        EXPECT_GT(info.stats.sah_cost, 1.0);
        const RayDiffResult d = run_ray_diff(scene, rays, *bvhs[s], *fresh, false);
        EXPECT_EQ(d.bvh_wrong(), 0u)
            << kind << " frame " << frame << " " << name(strategies[s]) << ": agree " << d.agree
            << ", ties " << d.ties << ", mismatches " << d.mismatches;
        EXPECT_EQ(d.agree + d.ties + d.mismatches, rays.size());
        const RayDiffResult o = run_ray_diff(scene, rays, *bvhs[s], *fresh, true);
        EXPECT_EQ(o.bvh_wrong(), 0u)
            << kind << " frame " << frame << " occluded " << name(strategies[s]);
      }
      bvh_mt->update(scene);
      EXPECT_FALSE(bvh_mt->info().rebuilt);
      EXPECT_EQ(run_ray_diff(scene, rays, *bvh_mt, *fresh, false).bvh_wrong(), 0u)
          << kind << " frame " << frame << " refit/mt";
      bvh_morton->update(scene);
      EXPECT_EQ(run_ray_diff(scene, rays, *bvh_morton, *fresh, false).bvh_wrong(), 0u)
          << kind << " frame " << frame << " adaptive/morton";
      EXPECT_EQ(run_ray_diff(scene, rays, *bvh_morton, *fresh, true).bvh_wrong(), 0u)
          << kind << " frame " << frame << " adaptive/morton occluded";
      // Embree's dynamic update answers as the fresh build does.
      std::vector<Hit> want(rays.size()), got(rays.size());
      fresh->intersect(rays, want);
      for (Intersector* e : {embree_refit.get(), embree_low.get()}) {
        e->update(scene);
        e->intersect(rays, got);
        const RayDiffResult d = diff_hits(scene, rays, got, want);
        EXPECT_EQ(d.mismatches, 0u) << kind << " frame " << frame << " " << e->info().name;
        EXPECT_GE(d.agree, rays.size() * 9 / 10);
      }
      EXPECT_FALSE(embree_refit->info().rebuilt);
      EXPECT_TRUE(embree_low->info().rebuilt);
    }
  });
  return run;
}

TEST(UpdateStrategies, TwistAgreesWithEmbree) { check_deformer("twist"); }
TEST(UpdateStrategies, BendAgreesWithEmbree) { check_deformer("bend"); }
TEST(UpdateStrategies, PulseAgreesWithEmbree) { check_deformer("pulse"); }

TEST(UpdateStrategies, AdaptiveKeepsRefittingAGentleWave) {
  const DeformRun r = check_deformer("wave");
  ASSERT_EQ(r.adaptive_rebuilt.size(), size_t(kFrames - 1));
  for (bool rebuilt : r.adaptive_rebuilt) EXPECT_FALSE(rebuilt);
}

TEST(UpdateStrategies, AdaptiveRebuildsDuringExplode) {
  const DeformRun r = check_deformer("explode");
  ASSERT_EQ(r.adaptive_rebuilt.size(), size_t(kFrames - 1));
  int rebuilds = 0;
  for (bool rebuilt : r.adaptive_rebuilt) rebuilds += rebuilt ? 1 : 0;
  EXPECT_GE(rebuilds, 1);
}

TEST(UpdateStrategies, AdaptiveDecisionFollowsTheFactor) {
  // Same explode, factor 100: the refitted tree never costs that much more.
  Scene scene = deformed_sphere(spec("explode"));
  run_with_threads(kStrategyThreads, [&] {
    const SceneAnimator animator(scene);
    animator.apply(0, scene);
    BackendOptions o;
    o.threads = kStrategyThreads;
    o.update = UpdateStrategy::kAdaptive;
    o.adaptive_factor = 100.0f;
    auto bvh = make_intersector("bvh", o);
    bvh->build(scene);
    const double built_cost = bvh->info().stats.sah_cost;
    for (int frame = 1; frame < kFrames; ++frame) {
      animator.apply(frame, scene);
      bvh->update(scene);
      EXPECT_FALSE(bvh->info().rebuilt);
      EXPECT_GT(bvh->info().stats.sah_cost, built_cost);  // the refitted tree degrades
      EXPECT_LT(bvh->info().stats.sah_cost, 100.0 * built_cost);
    }
  });
}

TEST(UpdateStrategies, ValidTriangleSetChangeForcesARebuild) {
  Scene scene = deformed_sphere(spec("wave"));
  run_with_threads(kStrategyThreads, [&] {
    for (UpdateStrategy u :
         {UpdateStrategy::kRefit, UpdateStrategy::kAdaptive, UpdateStrategy::kAuto}) {
      Scene s = scene;
      auto bvh = bvh_backend(u);
      bvh->build(s);
      const size_t n = bvh->info().stats.triangles;
      // Collapse triangle 10: it must leave the tree.
      const Vec3u t = s.meshes[0].triangles[10];
      s.meshes[0].positions[t[1]] = s.meshes[0].positions[t[0]];
      bvh->update(s);
      EXPECT_TRUE(bvh->info().rebuilt) << name(u);
      EXPECT_LT(bvh->info().stats.triangles, n);
      // Restore it: valid again, rebuilt again, and back in the tree.
      s.meshes[0].positions = scene.meshes[0].positions;
      bvh->update(s);
      EXPECT_TRUE(bvh->info().rebuilt) << name(u);
      EXPECT_EQ(bvh->info().stats.triangles, n);
      // Nothing changed: a refit.
      bvh->update(s);
      EXPECT_FALSE(bvh->info().rebuilt) << name(u);
      auto fresh = embree_backend("medium");
      fresh->build(s);
      const std::vector<Ray> rays = make_rays(s, RayKind::kPrimary, kStrategyRays, 3);
      EXPECT_EQ(run_ray_diff(s, rays, *bvh, *fresh, false).bvh_wrong(), 0u);
    }
  });
}

}  // namespace
}  // namespace hprt

namespace hprt {
namespace {

// Auto with a heavy query load per frame (many random rays on a small
// exploding mesh: far more query time than a rebuild) rebuilds, and says
// with which builder; its answers stay right. (Which builder it picks is
// auto_update_policy's, tested on fixed figures in test_auto_update_policy.)
TEST(UpdateStrategies, AutoRebuildsAHeavilyQueriedExplosion) {
  Scene scene = deformed_sphere(spec("explode"));
  run_with_threads(kStrategyThreads, [&] {
    const SceneAnimator animator(scene);
    animator.apply(0, scene);
    auto bvh = bvh_backend(UpdateStrategy::kAuto);
    bvh->build(scene);
    EXPECT_EQ(bvh->info().rebuilt_with, "parallel");
    const std::vector<Ray> load = make_rays(scene, RayKind::kRandom, 200'000, 7);
    std::vector<Hit> hits(load.size());
    int rebuilds = 0;
    for (int frame = 1; frame < kFrames; ++frame) {
      for (int pass = 0; pass < 4; ++pass) bvh->intersect(load, hits);
      animator.apply(frame, scene);
      bvh->update(scene);
      const BuildInfo info = bvh->info();
      if (info.rebuilt) {
        EXPECT_TRUE(info.rebuilt_with == "morton" || info.rebuilt_with == "parallel")
            << "frame " << frame << ": " << info.rebuilt_with;
        ++rebuilds;
      } else {
        EXPECT_EQ(info.rebuilt_with, "") << "frame " << frame;
      }
      auto fresh = embree_backend("medium");
      fresh->build(scene);
      const std::vector<Ray> rays = make_rays(scene, RayKind::kPrimary, kStrategyRays, 11 + frame);
      EXPECT_EQ(run_ray_diff(scene, rays, *bvh, *fresh, false).bvh_wrong(), 0u) << frame;
    }
    EXPECT_GE(rebuilds, 2);
  });
}

// Auto before any query time is known follows the adaptive rule: a gentle
// wave only refits, an explosion rebuilds, with the cheaper (Morton) build.
TEST(UpdateStrategies, AutoWithoutQueriesFollowsTheAdaptiveRule) {
  for (const char* kind : {"wave", "explode"}) {
    Scene scene = deformed_sphere(spec(kind));
    run_with_threads(kStrategyThreads, [&] {
      const SceneAnimator animator(scene);
      animator.apply(0, scene);
      auto bvh = bvh_backend(UpdateStrategy::kAuto);
      bvh->build(scene);
      int rebuilds = 0;
      for (int frame = 1; frame < kFrames; ++frame) {
        animator.apply(frame, scene);
        bvh->update(scene);
        if (bvh->info().rebuilt) {
          ++rebuilds;
          EXPECT_EQ(bvh->info().rebuilt_with, "morton") << kind << " frame " << frame;
        }
      }
      if (std::string(kind) == "wave")
        EXPECT_EQ(rebuilds, 0);
      else
        EXPECT_GE(rebuilds, 1);
    });
  }
}

}  // namespace
}  // namespace hprt
