// `hprt render` and `hprt validate image` end to end: image files and JSON
// fields, thread-count independence, exit codes 0/1/2, and bad input leaving
// no output file behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "io/image/image_io.h"
#include "tests/support/cli_test_support.h"

namespace fs = std::filesystem;

namespace hprt {
namespace {

using test::CliResult;
using test::slurp;

class CliRender : public test::CliTest {
 protected:
  CliRender() : CliTest("hprt_cli_render_") {}
  void SetUp() override {
    CliTest::SetUp();
    std::ofstream(dir_ / "scene.json") << R"({
      "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "focal_length_mm": 20,
                 "width": 64, "height": 48},
      "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [1, 1, 1]}],
      "meshes": [
        {"generate": {"kind": "plane", "tris": 2}, "transform": {"scale": 4},
         "material": {"diffuse": [0.6, 0.6, 0.6], "reflectivity": 0.3}},
        {"generate": {"kind": "sphere", "tris": 2000}, "transform": {"translate": [0, 1, 0]},
         "material": {"diffuse": [0.8, 0.2, 0.2], "specular": [0.5, 0.5, 0.5]}}
      ]})";
  }
  // Files in the directory other than the scene: no stray temporaries.
  size_t output_files() const {
    size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename() != "scene.json") ++n;
    return n;
  }
};

TEST_F(CliRender, WritesPngAndJson) {
  const CliResult r = run("render " + path("scene.json") + " --backend embree --threads 2 -o " +
                          path("a.png") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["backend"], "embree");
  EXPECT_EQ(j["width"], 64);
  EXPECT_EQ(j["height"], 48);
  EXPECT_EQ(j["threads"], 2);
  EXPECT_GT(j["triangles"].get<int>(), 2000);
  EXPECT_GE(j["rays"].get<int>(), 64 * 48);
  EXPECT_EQ(j["primary_rays"], 64 * 48);
  EXPECT_GT(j["mrays_per_s"].get<double>(), 0.0);
  for (const char* key : {"config", "build_ms", "render_ms", "output"})
    EXPECT_TRUE(j.contains(key)) << key;
  const Image img = read_image(path("a.png"));
  EXPECT_EQ(img.width, 64);
  EXPECT_EQ(img.height, 48);
  EXPECT_NE(r.err.find("hprt render:"), std::string::npos);
}

TEST_F(CliRender, OverridesAndExr) {
  const CliResult r =
      run("render " + path("scene.json") + " --backend embree --width 40 --height 30 " +
          "--focal 35 -o " + path("a.exr"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Image img = read_image(path("a.exr"));
  EXPECT_EQ(img.width, 40);
  EXPECT_EQ(img.height, 30);
  // Width alone keeps the scene's 4:3 aspect ratio.
  ASSERT_EQ(
      run("render " + path("scene.json") + " --backend embree --width 32 -o " + path("b.png")).code,
      0);
  EXPECT_EQ(read_image(path("b.png")).height, 24);
}

TEST_F(CliRender, ThreadCountDoesNotChangeImageAndValidatePasses) {
  ASSERT_EQ(
      run("render " + path("scene.json") + " --backend embree --threads 1 -o " + path("t1.png"))
          .code,
      0);
  ASSERT_EQ(
      run("render " + path("scene.json") + " --backend embree --threads 2 -o " + path("t2.png"))
          .code,
      0);
  EXPECT_EQ(slurp(dir_ / "t1.png"), slurp(dir_ / "t2.png"));
  const CliResult v = run("validate image " + path("t1.png") + " " + path("t2.png") + " --json");
  ASSERT_EQ(v.code, 0) << v.err;
  const auto j = nlohmann::json::parse(v.out);
  EXPECT_TRUE(j["psnr_db"].is_null());  // infinite
  EXPECT_EQ(j["identical"], true);
  EXPECT_EQ(j["rmse"], 0.0);
  EXPECT_EQ(j["pixels_over"], 0);
  EXPECT_EQ(j["pixels"], 64 * 48);
  EXPECT_EQ(j["pass"], true);
}

TEST_F(CliRender, ValidateImageFailsOnDifferentImages) {
  ASSERT_EQ(run("render " + path("scene.json") + " --backend embree -o " + path("a.png")).code, 0);
  ASSERT_EQ(
      run("render " + path("scene.json") + " --backend embree --focal 24 -o " + path("b.png")).code,
      0);
  const CliResult v = run("validate image " + path("a.png") + " " + path("b.png") +
                          " --json --diff " + path("d.png"));
  EXPECT_EQ(v.code, 1) << v.err;
  const auto j = nlohmann::json::parse(v.out);
  EXPECT_EQ(j["pass"], false);
  EXPECT_GT(j["pixels_over"].get<int>(), 0);
  EXPECT_LT(j["psnr_db"].get<double>(), 40.0);
  EXPECT_GT(j["max_error"].get<double>(), 0.01);
  EXPECT_EQ(read_image(path("d.png")).width, 64);
  // Loose enough limits pass.
  EXPECT_EQ(run("validate image " + path("a.png") + " " + path("b.png") +
                " --min-psnr 1 --threshold 1 --max-pixels-over 0")
                .code,
            0);
}

TEST_F(CliRender, BadInputExitsTwoAndLeavesNothing) {
  const std::string scene = path("scene.json");
  EXPECT_EQ(run("render " + scene + " --backend embree --width 0 -o " + path("a.png")).code, 2);
  EXPECT_EQ(run("render " + scene + " --backend embree -o " + path("missing/a.png")).code, 2);
  const CliResult ext = run("render " + scene + " --backend embree -o " + path("a.notanimage"));
  EXPECT_EQ(ext.code, 2);
  EXPECT_NE(ext.err.find("hprt: error:"), std::string::npos) << ext.err;
  EXPECT_EQ(run("render " + path("nosuchscene.json") + " -o " + path("a.png")).code, 2);
  EXPECT_EQ(output_files(), 0u);
  // validate image: different sizes and unreadable files are input errors.
  ASSERT_EQ(run("render " + scene + " --backend embree -o " + path("a.png")).code, 0);
  ASSERT_EQ(run("render " + scene + " --backend embree --width 32 -o " + path("b.png")).code, 0);
  const CliResult size = run("validate image " + path("a.png") + " " + path("b.png"));
  EXPECT_EQ(size.code, 2);
  EXPECT_NE(size.err.find("64x48 vs 32x24"), std::string::npos) << size.err;
  EXPECT_EQ(run("validate image " + path("a.png") + " " + path("nothere.png")).code, 2);
  std::ofstream(dir_ / "junk.png") << "not a png";
  EXPECT_EQ(run("validate image " + path("a.png") + " " + path("junk.png")).code, 2);
}

// OpenImageIO lives in the image codec module (io/image/image_codec.h): commands
// that touch no image never load it, and one that does loads it on first use.
TEST_F(CliRender, OnlyImageCommandsLoadOpenImageIO) {
  const std::string scene = path("scene.json");
  const CliResult trace = run("build " + scene, "LD_DEBUG=libs ");
  ASSERT_EQ(trace.code, 0) << trace.err;
  EXPECT_NE(trace.err.find("libembree3"), std::string::npos) << "LD_DEBUG shows no libraries?";
  EXPECT_EQ(trace.err.find("libOpenImageIO"), std::string::npos);
  const CliResult render =
      run("render " + scene + " --backend embree -o " + path("a.png"), "LD_DEBUG=libs ");
  ASSERT_EQ(render.code, 0) << render.err;
  EXPECT_NE(render.err.find("libhprt_oiio"), std::string::npos);
  EXPECT_NE(render.err.find("libOpenImageIO"), std::string::npos);
}

TEST_F(CliRender, MissingImageModuleIsAOneLineErrorAndNoFile) {
  const CliResult r = run("render " + path("scene.json") + " --backend embree -o " + path("a.png"),
                          "HPRT_IMAGE_MODULE=" + path("nothere.so") + " ");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(path("a.png") + ": image support unavailable: no libhprt_oiio.so at " +
                       path("nothere.so")),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(output_files(), 0u);
  // A file that is not the module is refused the same way.
  std::ofstream(dir_ / "fake.so") << "not a shared object";
  const CliResult fake = run("render " + path("scene.json") + " -o " + path("a.png"),
                             "HPRT_IMAGE_MODULE=" + path("fake.so") + " ");
  EXPECT_EQ(fake.code, 2);
  EXPECT_NE(fake.err.find("image support unavailable"), std::string::npos) << fake.err;
  EXPECT_FALSE(fs::exists(path("a.png")));
}

}  // namespace
}  // namespace hprt
