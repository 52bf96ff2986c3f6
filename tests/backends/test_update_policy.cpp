// When the bvh backend's update() rebuilds (update_policy.h), and what a
// tree was built over (MeshRecord): changed counts, a left-out triangle that
// became valid, and a mesh count change read nothing out of range.
#include <gtest/gtest.h>

#include <limits>

#include "backends/mesh_record.h"
#include "backends/update_policy.h"
#include "bvh/input/prim_info.h"
#include "meshgen/mesh_generators.h"

namespace hprt {
namespace {

TEST(UpdatePolicy, RebuildAlwaysRebuilds) {
  EXPECT_TRUE(must_rebuild(UpdateStrategy::kRebuild, true));
  EXPECT_TRUE(must_rebuild(UpdateStrategy::kRebuild, false));
}

TEST(UpdatePolicy, RefitAdaptiveAndAutoRefitWhileTheTreeFits) {
  for (UpdateStrategy s :
       {UpdateStrategy::kRefit, UpdateStrategy::kAdaptive, UpdateStrategy::kAuto}) {
    EXPECT_FALSE(must_rebuild(s, true));
    EXPECT_TRUE(must_rebuild(s, false));
  }
}

TEST(UpdatePolicy, AdaptiveRebuildsPastTheFactor) {
  BackendOptions o;
  o.update = UpdateStrategy::kAdaptive;
  o.adaptive_factor = 1.5f;
  EXPECT_FALSE(rebuild_after_refit(o, true, 149.0, 100.0));
  EXPECT_FALSE(rebuild_after_refit(o, true, 150.0, 100.0));  // at the factor: keep
  EXPECT_TRUE(rebuild_after_refit(o, true, 150.5, 100.0));
  EXPECT_TRUE(rebuild_after_refit(o, false, 90.0, 100.0));  // the refit dropped a triangle
  for (UpdateStrategy s : {UpdateStrategy::kRefit, UpdateStrategy::kAuto}) {
    o.update = s;  // refit keeps any cost; auto decides elsewhere
    EXPECT_FALSE(rebuild_after_refit(o, true, 1e9, 100.0));
    EXPECT_TRUE(rebuild_after_refit(o, false, 90.0, 100.0));
  }
}

Scene sphere_and_torus() {
  Scene s;
  s.add_mesh(generate_sphere(500));
  s.add_mesh(generate_torus(300));
  return s;
}

TEST(MeshRecord, FitsTheSceneItRecorded) {
  Scene s = sphere_and_torus();
  MeshRecord r;
  r.record(s, make_prim_info(s));
  EXPECT_TRUE(r.fits(s));
  s.meshes[0].positions[0].x += 0.01f;  // moved vertices still fit
  EXPECT_TRUE(r.fits(s));
  r.clear();
  EXPECT_FALSE(r.fits(s));
}

TEST(MeshRecord, ChangedCountsDoNotFit) {
  Scene s = sphere_and_torus();
  MeshRecord r;
  r.record(s, make_prim_info(s));
  Scene fewer = s;
  fewer.meshes.pop_back();
  EXPECT_FALSE(r.fits(fewer));
  Scene more = s;
  more.add_mesh(generate_sphere(80));
  EXPECT_FALSE(r.fits(more));
  Scene fewer_triangles = s;
  fewer_triangles.meshes[1].triangles.pop_back();
  EXPECT_FALSE(r.fits(fewer_triangles));
}

TEST(MeshRecord, ALeftOutTriangleBecomingValidDoesNotFit) {
  Scene s = sphere_and_torus();
  const Vec3f saved = s.meshes[1].positions[s.meshes[1].triangles[7][0]];
  s.meshes[1].positions[s.meshes[1].triangles[7][0]].y = std::numeric_limits<float>::quiet_NaN();
  const PrimInfo prims = make_prim_info(s);
  ASSERT_GT(prims.invalid, 0u);
  MeshRecord r;
  r.record(s, prims);
  EXPECT_TRUE(r.fits(s));
  // With the mesh count changed too, nothing past the meshes is read.
  Scene fewer = s;
  fewer.meshes.resize(1);
  EXPECT_FALSE(r.fits(fewer));
  s.meshes[1].positions[s.meshes[1].triangles[7][0]] = saved;
  EXPECT_FALSE(r.fits(s));
}

}  // namespace
}  // namespace hprt
