// SceneAnimator: frame k depends only on k (apply 7 then 3 equals 3 directly,
// bit for bit, for every deformer), sizes and topology never change, explode
// meshes are unwelded at set-up, normals are recomputed, per-frame file
// sequences load with the mesh's placement and reject other topologies.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>

#include "anim/scene_animator.h"
#include "core/error.h"
#include "core/frame_pattern.h"
#include "core/parallel.h"
#include "io/mesh/ply_writer.h"
#include "io/scene/scene_reader.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/cli_test_support.h"

namespace fs = std::filesystem;

// Counts every operator new of this test program, to check that animating a
// frame allocates nothing. Not inlined: inlined, g++ 12 sees malloc's
// pointer reach operator delete, or free() get operator new's, and warns
// (-Wmismatched-new-delete).
static std::atomic<long> g_allocations{0};
[[gnu::noinline]] void* operator new(size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, size_t) noexcept { std::free(p); }

namespace hprt {
namespace {

Scene scene_with(const std::vector<std::string>& kinds) {
  Scene scene;
  for (size_t i = 0; i < kinds.size(); ++i) {
    TriangleMesh m = generate_torus(3000);
    for (Vec3f& p : m.positions) p += Vec3f(float(i) * 3.0f, 0.0f, 0.0f);
    scene.add_mesh(std::move(m));
    DeformerSpec d;
    d.mesh = int(i);
    d.kind = kinds[i];
    d.amplitude = 0.2f;
    scene.animation.deformers.push_back(d);
  }
  scene.animation.frames = 10;
  scene.animation.fps = 7.0f;  // t = 3/7 s: no deformer is at a zero of its cycle
  return scene;
}

TEST(SceneAnimator, FrameDependsOnlyOnItsNumber) {
  const std::vector<std::string> kinds{"twist", "bend", "wave", "pulse", "explode"};
  Scene a = scene_with(kinds), b = scene_with(kinds);
  const SceneAnimator anim_a(a), anim_b(b);
  EXPECT_TRUE(anim_a.animated());
  EXPECT_EQ(anim_a.frames(), 10);
  run_with_threads(2, [&] {
    anim_a.apply(7, a);
    anim_a.apply(3, a);
  });
  run_with_threads(1, [&] { anim_b.apply(3, b); });
  for (size_t i = 0; i < kinds.size(); ++i) {
    EXPECT_EQ(a.meshes[i].positions, b.meshes[i].positions) << kinds[i];
    EXPECT_EQ(a.meshes[i].triangles, b.meshes[i].triangles) << kinds[i];
  }
  // And frame 3 is not the rest pose nor frame 7.
  Scene rest = scene_with(kinds);
  const SceneAnimator anim_rest(rest);
  for (size_t i = 0; i < kinds.size(); ++i)
    EXPECT_NE(a.meshes[i].positions, rest.meshes[i].positions) << kinds[i];
}

TEST(SceneAnimator, KeepsSizesTopologyAndBuffers) {
  Scene scene = scene_with({"wave", "explode"});
  const size_t wave_vertices = scene.meshes[0].positions.size();
  const std::vector<Vec3u> wave_topology = scene.meshes[0].triangles.to_vector();
  const size_t explode_tris = scene.meshes[1].triangles.size();
  const SceneAnimator anim(scene);
  // Set-up unwelded the exploding mesh only.
  EXPECT_EQ(scene.meshes[0].positions.size(), wave_vertices);
  EXPECT_EQ(scene.meshes[1].positions.size(), 3 * explode_tris);
  EXPECT_TRUE(scene.meshes[1].padded_for_embree());
  const Vec3f* data0 = scene.meshes[0].positions.data();
  const Vec3f* data1 = scene.meshes[1].positions.data();
  const std::vector<Vec3u> explode_topology = scene.meshes[1].triangles.to_vector();
  for (int k : {0, 4, 9, 1}) {
    anim.apply(k, scene);
    EXPECT_EQ(scene.meshes[0].positions.data(), data0);  // in place: Embree's buffers stay valid
    EXPECT_EQ(scene.meshes[1].positions.data(), data1);
    EXPECT_EQ(scene.meshes[0].triangles, wave_topology);
    EXPECT_EQ(scene.meshes[1].triangles, explode_topology);
  }
  EXPECT_THROW(anim.apply(10, scene), InputError);
  EXPECT_THROW(anim.apply(-1, scene), InputError);
}

TEST(SceneAnimator, StaticSceneIsNotAnimated) {
  Scene scene;
  scene.add_mesh(generate_sphere(100));
  const std::vector<Vec3f> before = scene.meshes[0].positions.to_vector();
  const SceneAnimator anim(scene);
  EXPECT_FALSE(anim.animated());
  EXPECT_EQ(anim.frames(), 1);
  anim.apply(0, scene);
  EXPECT_EQ(scene.meshes[0].positions, before);
}

TEST(SceneAnimator, RecomputesNormalsOfMeshesWithNormals) {
  Scene scene;
  scene.add_mesh(generate_sphere(5000));
  TriangleMesh& m = scene.meshes[0];
  m.normals.assign(m.positions.size(), Vec3f(0.0f, 0.0f, 1.0f));  // deliberately wrong
  DeformerSpec d;
  d.kind = "pulse";
  d.amplitude = 0.3f;
  scene.animation.deformers.push_back(d);
  scene.animation.frames = 4;
  const SceneAnimator anim(scene);
  anim.apply(2, scene);
  // Still a (scaled) unit sphere about the origin: normals are radial.
  for (size_t v = 0; v < m.positions.size(); ++v) {
    EXPECT_NEAR(length(m.normals[v]), 1.0f, 1e-5f);
    EXPECT_GT(dot(m.normals[v], normalize(m.positions[v])), 0.99f) << v;
  }
}

TEST(SceneAnimator, DeformerFramesAllocateNothing) {
  Scene scene = scene_with({"twist", "bend", "wave", "pulse", "explode"});
  scene.meshes[0].normals.assign(scene.meshes[0].positions.size(), Vec3f(0.0f, 1.0f, 0.0f));
  const SceneAnimator anim(scene);
  EXPECT_GT(g_allocations.load(), 0);  // the counter does see this program's allocations
  run_with_threads(2, [&] {
    anim.apply(1, scene);  // warm-up: the task arena's own set-up
    const long before = g_allocations.load();
    for (int k = 2; k < 10; ++k) anim.apply(k, scene);
    EXPECT_EQ(g_allocations.load() - before, 0);
  });
}

class SceneAnimatorFiles : public test::TempDirTest {
 protected:
  SceneAnimatorFiles() : TempDirTest("hprt_anim_") {}
  void SetUp() override {
    TempDirTest::SetUp();
    base_ = generate_sphere(500);
    write_ply(base_, path("mesh.ply"));
    for (int k = 0; k < 3; ++k) {  // frames 10, 11, 12: the sphere scaled by 1 + k/10
      TriangleMesh f = base_;
      for (Vec3f& p : f.positions) p *= 1.0f + 0.1f * float(k);
      write_ply(f, format_frame_path(path("seq_%03d.ply"), 10 + k));
    }
  }
  void write_scene(int frames) const {
    std::ofstream(path("scene.json"))
        << R"({"meshes": [{"file": "mesh.ply", "transform": {"translate": [0, 5, 0]}}],
              "animation": {"frames": )"
        << frames << R"(, "sequences": [{"mesh": 0, "pattern": "seq_%03d.ply", "first": 10}]}})";
  }

  TriangleMesh base_;
};

TEST_F(SceneAnimatorFiles, SequenceFramesArePlacedLikeTheMesh) {
  write_scene(3);
  Scene scene = load_scene(path("scene.json"));
  const SceneAnimator anim(scene);
  anim.apply(2, scene);
  anim.apply(1, scene);
  for (size_t v = 0; v < base_.positions.size(); v += 7) {
    const Vec3f expect = base_.positions[v] * 1.1f + Vec3f(0.0f, 5.0f, 0.0f);
    EXPECT_NEAR(scene.meshes[0].positions[v].x, expect.x, 1e-5f);
    EXPECT_NEAR(scene.meshes[0].positions[v].y, expect.y, 1e-5f);
    EXPECT_NEAR(scene.meshes[0].positions[v].z, expect.z, 1e-5f);
  }
}

TEST_F(SceneAnimatorFiles, MissingFrameFileIsAnErrorNamingIt) {
  write_scene(4);  // frame 3 = seq_013.ply does not exist
  Scene scene = load_scene(path("scene.json"));
  try {
    SceneAnimator anim(scene);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("seq_013.ply"), std::string::npos) << e.what();
  }
}

TEST_F(SceneAnimatorFiles, OtherTopologyIsAnErrorNamingTheFile) {
  write_scene(3);
  TriangleMesh swapped = base_;  // same counts, two triangles' indices rotated
  std::swap(swapped.triangles[5][0], swapped.triangles[5][1]);
  write_ply(swapped, path("seq_011.ply"));
  TriangleMesh other = generate_sphere(2000);  // other counts
  write_ply(other, path("seq_012.ply"));
  Scene scene = load_scene(path("scene.json"));
  const SceneAnimator anim(scene);
  anim.apply(0, scene);
  for (int k : {1, 2}) {
    try {
      anim.apply(k, scene);
      FAIL() << "no error for frame " << k;
    } catch (const InputError& e) {
      const std::string name = k == 1 ? "seq_011.ply" : "seq_012.ply";
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("topology"), std::string::npos) << e.what();
    }
  }
}

TEST(FramePattern, FormatsLikePrintf) {
  EXPECT_EQ(format_frame_path("out_%04d.png", 7), "out_0007.png");
  EXPECT_EQ(format_frame_path("out_%d.png", 12345), "out_12345.png");
  EXPECT_EQ(format_frame_path("out_%3d.png", 7), "out_  7.png");
  EXPECT_EQ(format_frame_path("100%%_%02d.png", 3), "100%_03.png");
  EXPECT_EQ(format_frame_path("still.png", 3), "still.png");
  EXPECT_TRUE(has_frame_number("a_%04d.png", "-o"));
  EXPECT_FALSE(has_frame_number("a_%%d.png", "-o"));
  EXPECT_THROW(has_frame_number("a_%s.png", "-o"), InputError);
  EXPECT_THROW(has_frame_number("a_%d_%d.png", "-o"), InputError);
  EXPECT_THROW(has_frame_number("a_%", "-o"), InputError);
}

}  // namespace
}  // namespace hprt
