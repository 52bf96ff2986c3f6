// Scene JSON reader: the docs/ARCHITECTURE.md example, defaults, strict field checks with
// JSON paths in errors, relative paths, transforms, material overrides, the
// bare-mesh scene (framing camera + head light), and the shipped scenes.
#include "io/scene/scene_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/camera.h"
#include "core/error.h"
#include "io/mesh/ply_writer.h"
#include "meshgen/mesh_generators.h"

namespace fs = std::filesystem;
namespace hprt {

namespace {

class SceneReader : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hprt_scene_reader_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  // load_scene must throw an InputError whose message contains `expected`.
  void expect_error(const std::string& json, const std::string& expected) {
    const std::string path = write("bad.json", json);
    try {
      load_scene(path);
      ADD_FAILURE() << "accepted: " << json;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(expected), std::string::npos) << "message: " << msg;
      EXPECT_EQ(msg.rfind(path, 0), 0u) << "message does not start with the file: " << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }

  fs::path dir_;
};

constexpr const char* kSphere20 = R"({"generate": {"kind": "sphere", "tris": 20}})";

std::string scene_with(const std::string& extra) {
  return std::string(R"({"meshes": [)") + kSphere20 + "]" + (extra.empty() ? "" : ", " + extra) +
         "}";
}

void expect_vec(const Vec3f& v, float x, float y, float z, float tol = 1e-5f) {
  EXPECT_NEAR(v.x, x, tol);
  EXPECT_NEAR(v.y, y, tol);
  EXPECT_NEAR(v.z, z, tol);
}

}  // namespace

TEST_F(SceneReader, DesignExample) {
  write_ply(generate_sphere(1000), (dir_ / "bunny.ply").string());
  const std::string path = write("scene.json", R"({
    "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "up": [0, 1, 0],
               "focal_length_mm": 13, "sensor_width_mm": 36, "width": 800, "height": 600},
    "background": [0.05, 0.05, 0.08],
    "ambient": [0.1, 0.1, 0.1],
    "max_depth": 5,
    "lights": [
      {"type": "point", "position": [3, 5, 2], "intensity": [1, 1, 1]},
      {"type": "directional", "direction": [-1, -1, -0.5], "intensity": [0.3, 0.3, 0.3]}
    ],
    "meshes": [
      {"file": "bunny.ply",
       "transform": {"scale": 1.0, "rotate_deg": [0, 90, 0], "translate": [0, 0, 0]},
       "material": {"diffuse": [0.8, 0.3, 0.2], "specular": [0.5, 0.5, 0.5],
                    "shininess": 64, "reflectivity": 0.2}},
      {"generate": {"kind": "sphere", "tris": 20000, "seed": 1},
       "material": {"diffuse": [0.2, 0.2, 0.2], "reflectivity": 0.8}}
    ],
    "animation": {"frames": 60, "fps": 24,
                  "deformers": [{"mesh": 0, "kind": "wave", "amplitude": 0.05, "wavelength": 0.5, "speed": 1.0}]}
  })");
  const Scene s = load_scene(path);
  expect_vec(s.camera.position, 0, 1, 5);
  EXPECT_EQ(s.camera.focal_length_mm, 13.0f);
  EXPECT_EQ(s.camera.sensor_width_mm, 36.0f);
  EXPECT_EQ(s.camera.width, 800);
  EXPECT_EQ(s.camera.height, 600);
  expect_vec(s.background, 0.05f, 0.05f, 0.08f);
  EXPECT_EQ(s.max_depth, 5);
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].type, LightType::kPoint);
  expect_vec(s.lights[0].position, 3, 5, 2);
  EXPECT_EQ(s.lights[1].type, LightType::kDirectional);
  expect_vec(s.lights[1].direction, -1, -1, -0.5f);
  expect_vec(s.lights[1].intensity, 0.3f, 0.3f, 0.3f);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].triangle_count(), 1280u);
  EXPECT_EQ(s.meshes[1].triangle_count(), 20480u);
  EXPECT_TRUE(s.meshes[0].padded_for_embree());
  EXPECT_TRUE(s.meshes[1].padded_for_embree());
  expect_vec(s.meshes[0].material.diffuse, 0.8f, 0.3f, 0.2f);
  expect_vec(s.meshes[0].material.specular, 0.5f, 0.5f, 0.5f);
  EXPECT_EQ(s.meshes[0].material.shininess, 64.0f);
  EXPECT_FLOAT_EQ(s.meshes[0].material.reflectivity, 0.2f);
  // Fields not given keep the defaults.
  EXPECT_EQ(s.meshes[1].material.specular, Material{}.specular);
  EXPECT_EQ(s.meshes[1].material.shininess, Material{}.shininess);
  EXPECT_FLOAT_EQ(s.meshes[1].material.reflectivity, 0.8f);
  EXPECT_EQ(s.animation.frames, 60);
  EXPECT_EQ(s.animation.fps, 24.0f);
  ASSERT_EQ(s.animation.deformers.size(), 1u);
  EXPECT_EQ(s.animation.deformers[0].kind, "wave");
  EXPECT_FLOAT_EQ(s.animation.deformers[0].wavelength, 0.5f);
  EXPECT_EQ(s.animation.deformers[0].axis, DeformerSpec{}.axis);
}

TEST_F(SceneReader, DefaultsWhenFieldsMissing) {
  const Scene s = load_scene(write("min.json", scene_with("")));
  const Scene def;
  EXPECT_EQ(s.background, def.background);
  EXPECT_EQ(s.ambient, def.ambient);
  EXPECT_EQ(s.max_depth, def.max_depth);
  EXPECT_EQ(s.animation.frames, 1);
  EXPECT_FALSE(s.animation.animated());
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].material, Material{});
  // No camera: framing camera with the default lens; no lights: a head light.
  EXPECT_EQ(s.camera.focal_length_mm, Camera{}.focal_length_mm);
  EXPECT_EQ(s.camera.width, Camera{}.width);
  EXPECT_NEAR(length(s.camera.look_at), 0.0f, 1e-6f);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].position, s.camera.position);
  // A camera with only some fields keeps the rest of the defaults; "lights": [] means none.
  const Scene p =
      load_scene(write("p.json", scene_with(R"("camera": {"width": 64}, "lights": [])")));
  EXPECT_EQ(p.camera.width, 64);
  EXPECT_EQ(p.camera.height, Camera{}.height);
  EXPECT_EQ(p.camera.position, Camera{}.position);
  EXPECT_TRUE(p.lights.empty());
  // Zero meshes is a valid (empty) scene.
  const Scene e = load_scene(write("e.json", R"({"meshes": []})"));
  EXPECT_EQ(e.triangle_count(), 0u);
}

TEST_F(SceneReader, UnknownFieldsNamed) {
  expect_error(scene_with(R"("backgorund": [0, 0, 0])"), "unknown field 'backgorund'");
  expect_error(scene_with(R"("camera": {"focal_lenght_mm": 13})"),
               "unknown field 'camera.focal_lenght_mm'");
  expect_error(
      R"({"meshes": [{"generate": {"kind": "sphere"}, "material": {"difuse": [1, 1, 1]}}]})",
      "unknown field 'meshes[0].material.difuse'");
  expect_error(
      scene_with(R"("lights": [{"type": "point"}, {"type": "point", "intensty": [1, 1, 1]}])"),
      "unknown field 'lights[1].intensty'");
  expect_error(scene_with(R"("lights": [{"type": "point", "direction": [0, -1, 0]}])"),
               "unknown field 'lights[0].direction'");
  expect_error(R"({"meshes": [{"generate": {"kind": "sphere", "tri": 5}}]})",
               "unknown field 'meshes[0].generate.tri'");
  expect_error(
      R"({"meshes": [{"generate": {"kind": "sphere"}, "transform": {"rotate": [0, 0, 0]}}]})",
      "unknown field 'meshes[0].transform.rotate'");
  expect_error(scene_with(R"("animation": {"deformers": [{"kind": "wave", "ampltude": 1}]})"),
               "unknown field 'animation.deformers[0].ampltude'");
}

TEST_F(SceneReader, DuplicateKeysNamed) {
  expect_error(scene_with(R"("background": [0, 0, 0], "background": [1, 1, 1])"),
               "JSON object with the key 'background' twice");
  expect_error(scene_with(R"("camera": {"width": 64, "height": 48, "width": 32})"),
               "JSON object with the key 'width' twice");
  expect_error(R"({"meshes": [{"generate": {"kind": "sphere", "kind": "torus"}}]})",
               "JSON object with the key 'kind' twice");
  // One key in two objects, or in an object and its parent, is no duplicate.
  const Scene s =
      load_scene(write("ok.json", R"({"meshes": [{"generate": {"kind": "sphere", "tris": 20}},
                                                 {"generate": {"kind": "torus", "tris": 20}}],
                                      "camera": {"width": 64, "height": 48}})"));
  EXPECT_EQ(s.meshes.size(), 2u);
  expect_error("{\"meshes\": " + std::string(100, '[') + std::string(100, ']') + "}",
               "JSON nested deeper than 64 levels");
}

TEST_F(SceneReader, WrongTypesAndValuesNamed) {
  expect_error(scene_with(R"("camera": {"width": "800"})"),
               "field 'camera.width': expected an integer");
  expect_error(scene_with(R"("camera": {"width": 0})"), "field 'camera.width'");
  expect_error(scene_with(R"("camera": {"height": -5})"), "field 'camera.height'");
  expect_error(scene_with(R"("camera": {"width": 20000, "height": 20000})"), "16384x16384");
  expect_error(scene_with(R"("camera": {"position": [0, 0, 0], "look_at": [0, 0, 0]})"),
               "field 'camera.look_at'");
  expect_error(scene_with(R"("camera": {"focal_length_mm": -1})"),
               "field 'camera.focal_length_mm'");
  expect_error(scene_with(R"("lights": [{"position": [1, 2]}])"),
               "field 'lights[0].position': expected an array of 3 numbers");
  expect_error(scene_with(R"("lights": [{"type": "spot"}])"), "unknown light type 'spot'");
  expect_error(scene_with(R"("lights": {"type": "point"})"), "field 'lights': expected an array");
  expect_error(scene_with(R"("max_depth": 65)"), "field 'max_depth'");
  expect_error(scene_with(R"("max_depth": -1)"), "field 'max_depth'");
  expect_error(scene_with(R"("ambient": [0.1, "x", 0.1])"),
               "field 'ambient[1]': expected a number");
  expect_error(scene_with(R"("background": [1e39, 0, 0])"), "field 'background[0]'");
  expect_error(R"({"camera": {}})", "missing field 'meshes'");
  expect_error(R"({"meshes": [{"file": "a.ply", "generate": {"kind": "sphere"}}]})",
               "field 'meshes[0]': needs exactly one of 'file' and 'generate'");
  expect_error(R"({"meshes": [{"material": {}}]})", "field 'meshes[0]': needs exactly one");
  expect_error(R"({"meshes": [{"generate": {"kind": "cube"}}]})",
               "field 'meshes[0].generate.kind'");
  expect_error(R"({"meshes": [{"generate": {"kind": "sphere", "tris": 0}}]})",
               "field 'meshes[0].generate.tris'");
  expect_error(R"({"meshes": [{"generate": {"kind": "subdivide"}}]})", "needs 'from'");
  expect_error(R"({"meshes": [{"generate": {"kind": "sphere"}, "transform": {"scale": "big"}}]})",
               "field 'meshes[0].transform.scale'");
  expect_error(R"({"meshes": [{"generate": {"kind": "sphere"}, "material": {"reflectivity": 2}}]})",
               "field 'meshes[0].material.reflectivity'");
  expect_error(scene_with(R"("animation": {"deformers": [{"mesh": 3, "kind": "wave"}]})"),
               "field 'animation.deformers[0].mesh'");
  expect_error(scene_with(R"("animation": {"deformers": [{"kind": "melt"}]})"),
               "field 'animation.deformers[0].kind'");
  expect_error(scene_with(R"("animation": {"sequences": [{"mesh": 0}]})"),
               "missing field 'pattern'");
  expect_error("[1, 2]", "expected a JSON object");
  expect_error(R"({"meshes": [}")", "parse error at line 1");
  expect_error("{\n  \"meshes\": []\n  \"camera\": {}\n}", "line 3");
  expect_error(R"({"meshes": [{"file": "missing.ply"}]})",
               "meshes[0]: " + (dir_ / "missing.ply").string());
}

TEST_F(SceneReader, TooLargeSceneFileRejected) {
  const std::string path = write("huge.json", "{}");
  fs::resize_file(path, (size_t{64} << 20) + 1);
  EXPECT_THROW(load_scene(path), InputError);
}

TEST_F(SceneReader, RelativePathsFromSceneDirectory) {
  fs::create_directories(dir_ / "meshes");
  write_ply(generate_torus(100), (dir_ / "meshes" / "t.ply").string());
  const std::string path = write("scenes/s.json",
                                 R"({"meshes": [{"file": "../meshes/t.ply"},
                                    {"generate": {"kind": "subdivide", "tris": 400, "from": "../meshes/t.ply"}}]})");
  const fs::path old = fs::current_path();
  fs::current_path(fs::temp_directory_path());
  const Scene s = load_scene(path);
  fs::current_path(old);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].triangle_count(), generate_torus(100).triangle_count());
  EXPECT_GE(s.meshes[1].triangle_count(), 400u);
}

TEST_F(SceneReader, TransformsScaleRotateTranslate) {
  TriangleMesh tri;
  tri.positions = {Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 1)};
  tri.triangles = {Vec3u{{0, 1, 2}}};
  const float r = 1.0f / std::sqrt(2.0f);
  tri.normals = {Vec3f(r, r, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 1)};
  write_ply(tri, (dir_ / "tri.ply").string());
  // Scale 2, rotate 90° about z, translate: (1,0,0) -> (2,0,0) -> (0,2,0) -> (1,4,3).
  Scene s = load_scene(write("a.json", R"({"meshes": [{"file": "tri.ply",
      "transform": {"scale": 2, "rotate_deg": [0, 0, 90], "translate": [1, 2, 3]}}]})"));
  expect_vec(s.meshes[0].positions[0], 1, 4, 3);
  expect_vec(s.meshes[0].positions[1], -1, 2, 3);  // (0,2,0) -> (-2,0,0) -> +t
  // X then Y: (0,1,0) -Rx90-> (0,0,1) -Ry90-> (1,0,0). (Y then X would give (0,0,1).)
  s = load_scene(write("b.json", R"({"meshes": [{"file": "tri.ply",
      "transform": {"rotate_deg": [90, 90, 0]}}]})"));
  expect_vec(s.meshes[0].positions[1], 1, 0, 0);
  // Non-uniform scale: normals by the inverse transpose, renormalised.
  s = load_scene(write("c.json", R"({"meshes": [{"file": "tri.ply",
      "transform": {"scale": [2, 1, 1]}}]})"));
  expect_vec(s.meshes[0].positions[0], 2, 0, 0);
  ASSERT_EQ(s.meshes[0].normals.size(), 3u);
  const Vec3f n = normalize(Vec3f(0.5f, 1.0f, 0.0f));
  expect_vec(s.meshes[0].normals[0], n.x, n.y, n.z);
}

TEST_F(SceneReader, JsonMaterialOverridesMtlFieldByField) {
  write("m.mtl", "newmtl red\nKd 0.9 0.1 0.1\nKs 0.4 0.4 0.4\nNs 50\n");
  write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  const Scene mtl = load_scene(write("a.json", R"({"meshes": [{"file": "m.obj"}]})"));
  expect_vec(mtl.meshes[0].material.diffuse, 0.9f, 0.1f, 0.1f);
  const Scene s = load_scene(write("b.json", R"({"meshes": [{"file": "m.obj",
      "material": {"specular": [0, 0, 0], "reflectivity": 0.5}}]})"));
  const Material& m = s.meshes[0].material;
  expect_vec(m.diffuse, 0.9f, 0.1f, 0.1f);  // from the .mtl
  expect_vec(m.specular, 0, 0, 0);          // from the JSON
  EXPECT_EQ(m.shininess, mtl.meshes[0].material.shininess);
  EXPECT_FLOAT_EQ(m.reflectivity, 0.5f);
}

TEST_F(SceneReader, BareMeshPathFramedWithHeadLight) {
  TriangleMesh sphere = generate_sphere(2000);
  for (Vec3f& p : sphere.positions) p = p * 3.0f + Vec3f(10.0f, 5.0f, -3.0f);
  const std::string path = (dir_ / "ball.ply").string();
  write_ply(sphere, path);
  const Scene s = load_scene(path);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangle_count(), sphere.triangle_count());
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::kPoint);
  EXPECT_EQ(s.lights[0].position, s.camera.position);
  EXPECT_EQ(s.camera.focal_length_mm, Camera{}.focal_length_mm);
  // The centre of the image looks at the mesh's centre, from +z and above.
  const Vec3f centre = s.meshes[0].bounds().center();
  EXPECT_GT(s.camera.position.z, centre.z);
  EXPECT_GT(s.camera.position.y, centre.y);
  const CameraRays rays(s.camera);
  const Ray mid = rays.ray(0.5f * s.camera.width, 0.5f * s.camera.height);
  const Vec3f to_centre = normalize(centre - s.camera.position);
  EXPECT_GT(dot(mid.dir, to_centre), 1.0f - 1e-6f);
  // Every vertex is inside the frame (the bounding sphere fits the smaller fov).
  const Vec3f fwd = rays.forward();
  const float half_v =
      std::atan(0.5f * 36.0f * s.camera.height / s.camera.width / s.camera.focal_length_mm);
  for (const Vec3f& p : s.meshes[0].positions)
    ASSERT_LE(std::acos(std::min(1.0f, dot(normalize(p - s.camera.position), fwd))), half_v);
}

TEST_F(SceneReader, FramingCameraHandlesEmptyBounds) {
  const Camera c = framing_camera(AABB(), Camera{});
  EXPECT_TRUE(is_finite(c.position));
  EXPECT_NE(c.position, c.look_at);
}

TEST(SceneReaderShipped, DataScenesLoad) {
  int count = 0;
  for (const auto& e : fs::directory_iterator(fs::path(HPRT_SOURCE_DIR) / "data" / "scenes")) {
    if (e.path().extension() != ".json") continue;
    SCOPED_TRACE(e.path().string());
    const Scene s = load_scene(e.path().string());
    EXPECT_GT(s.triangle_count(), 0u);
    ++count;
  }
  EXPECT_GE(count, 1);
}

}  // namespace hprt
