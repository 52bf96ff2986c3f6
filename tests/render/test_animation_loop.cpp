// run_animation (render/animation_loop.h): the first frame is built, later
// ones updated, frames run in order, each rendered once (the first only when
// asked), and what it leaves equals frame k animated and built afresh.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "anim/scene_animator.h"
#include "backends/intersector.h"
#include "meshgen/mesh_generators.h"
#include "render/animation_loop.h"
#include "render/whitted.h"

namespace hprt {
namespace {

Scene wave_scene() {
  Scene s;
  s.add_mesh(generate_plane(2000));
  s.add_mesh(generate_torus(1500));
  s.animation.frames = 6;
  DeformerSpec wave;
  wave.mesh = 0;
  wave.kind = "wave";
  wave.amplitude = 0.05f;
  s.animation.deformers.push_back(wave);
  DeformerSpec twist;
  twist.mesh = 1;
  twist.kind = "twist";
  s.animation.deformers.push_back(twist);
  s.camera.width = 32;
  s.camera.height = 24;
  return s;
}

std::vector<Vec3f> image(const Scene& scene, const Intersector& backend) {
  const Framebuffer fb = render_whitted(scene, scene.camera, backend);
  return std::vector<Vec3f>(fb.pixels().begin(), fb.pixels().end());
}

TEST(AnimationLoop, BuildsFirstUpdatesLaterAndRendersEachFrame) {
  for (const bool render_first : {true, false}) {
    Scene scene = wave_scene();
    const SceneAnimator animator(scene);
    BackendOptions o;
    o.update = UpdateStrategy::kRefit;
    auto backend = make_intersector("bvh", o);
    std::vector<int> rendered, done;
    const auto render = [&](int k, RenderStats& stats) {
      rendered.push_back(k);
      render_whitted(scene, scene.camera, *backend, &stats);
      return 1.5;
    };
    const auto on_frame = [&](const AnimationFrame& f) {
      done.push_back(f.frame);
      EXPECT_EQ(f.rendered, f.frame != 2 || render_first);
      EXPECT_EQ(f.render_ms, f.rendered ? 1.5 : 0.0);
      EXPECT_EQ(f.stats.rays() > 0, f.rendered);
      EXPECT_GE(f.update_ms, 0.0);
      EXPECT_GE(f.animate_ms, 0.0);
      // The first frame is a build; a refit backend refits the others.
      EXPECT_EQ(f.info.rebuilt, f.frame == 2);
    };
    run_animation(scene, animator, *backend, {2, 5, render_first}, render, on_frame);
    EXPECT_EQ(done, (std::vector<int>{2, 3, 4}));
    EXPECT_EQ(rendered, render_first ? (std::vector<int>{2, 3, 4}) : (std::vector<int>{3, 4}));

    // What the loop leaves is frame 4: the same vertices and image as frame
    // 4 animated and built from scratch.
    Scene fresh = wave_scene();
    const SceneAnimator fresh_animator(fresh);
    fresh_animator.apply(4, fresh);
    for (size_t m = 0; m < scene.meshes.size(); ++m)
      ASSERT_EQ(std::memcmp(scene.meshes[m].positions.data(), fresh.meshes[m].positions.data(),
                            scene.meshes[m].positions.size() * sizeof(Vec3f)),
                0);
  }
}

TEST(AnimationLoop, LeavesTheImageOfAFreshBuild) {
  // With rebuilds every frame the tree is the one a fresh build makes (the
  // builders are deterministic), so the last frame's image is bit-identical.
  Scene scene = wave_scene();
  const SceneAnimator animator(scene);
  BackendOptions o;
  o.update = UpdateStrategy::kRebuild;
  auto backend = make_intersector("bvh", o);
  int updates = 0;
  run_animation(
      scene, animator, *backend, {0, 4, false}, [](int, RenderStats&) { return 0.0; },
      [&](const AnimationFrame& f) { updates += f.frame > 0 && f.info.rebuilt; });
  EXPECT_EQ(updates, 3);
  Scene fresh = wave_scene();
  const SceneAnimator fresh_animator(fresh);
  fresh_animator.apply(3, fresh);
  auto fresh_backend = make_intersector("bvh", o);
  fresh_backend->build(fresh);
  EXPECT_EQ(image(scene, *backend), image(fresh, *fresh_backend));
}

}  // namespace
}  // namespace hprt
