// Regression: every data scene rendered small with each backend matches its
// golden image (data/golden, made with Embree by scripts/update_golden.sh),
// and the two backends match each other more tightly still.
#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "backends/intersector.h"
#include "core/parallel.h"
#include "io/image/image_io.h"
#include "io/scene/scene_reader.h"
#include "render/whitted.h"
#include "validators/image_diff.h"

namespace hprt {
namespace {

// Golden images are 8-bit PNGs: a re-render on the same machine matches
// exactly (infinite PSNR). 40 dB leaves room for another CPU's Embree kernels
// (SSE/AVX2/AVX-512 round differently): an RMSE of 1 %, far below what a
// changed shading term, camera or scene gives (those fall under 30 dB).
constexpr double kMinPsnrVsGolden = 40.0;
// bvh against embree: same rays, same shading, so only ties (a shared edge
// hit on the other triangle) and Embree's non-watertight leaks differ, a
// handful of pixels: 50 dB allows ~3 pixels fully wrong at 160 x 120.
constexpr double kMinPsnrBetweenBackends = 50.0;

struct GoldenScene {
  const char* name;
  int width;
  int height;
};
// Sizes must match scripts/update_golden.sh.
constexpr GoldenScene kScenes[] = {
    {"single_6mm", 160, 120}, {"single_13mm", 160, 120}, {"combo", 160, 120}, {"hires", 192, 108}};

std::string scene_path(const GoldenScene& s) {
  return std::string(HPRT_SOURCE_DIR) + "/data/scenes/" + s.name + ".json";
}
std::string golden_path(const GoldenScene& s) {
  return std::string(HPRT_SOURCE_DIR) + "/data/golden/" + s.name + ".png";
}

// Renders the scene at the golden size and returns what its PNG would hold.
Image render_small(const GoldenScene& gs, const std::string& backend) {
  const Scene scene = load_scene(scene_path(gs));
  Camera camera = scene.camera;
  camera.width = gs.width;
  camera.height = gs.height;
  const Framebuffer fb = run_with_threads(2, [&] {
    BackendOptions options;
    options.backend = backend;
    options.threads = 2;
    auto intersector = make_intersector(backend, options);
    intersector->build(scene);
    return render_whitted(scene, camera, *intersector);
  });
  return encode_srgb8(fb.width(), fb.height(), fb.pixels());
}

class RenderGolden : public ::testing::TestWithParam<std::tuple<GoldenScene, std::string>> {};

TEST_P(RenderGolden, MatchesGoldenImage) {
  const auto& [gs, backend] = GetParam();
  const Image golden = read_image(golden_path(gs));
  ASSERT_EQ(golden.width, gs.width);
  ASSERT_EQ(golden.height, gs.height);
  const Image img = render_small(gs, backend);
  const ImageDiff d = diff_images(img, golden);
  EXPECT_GE(d.psnr_db, kMinPsnrVsGolden)
      << gs.name << " with " << backend << ": RMSE " << d.rmse << ", max error " << d.max_error
      << " at (" << d.max_x << ", " << d.max_y << "), " << d.pixels_over << " pixels over";
}

INSTANTIATE_TEST_SUITE_P(Scenes, RenderGolden,
                         ::testing::Combine(::testing::ValuesIn(kScenes),
                                            ::testing::Values("embree", "bvh")),
                         [](const auto& info) {
                           return std::string(std::get<0>(info.param).name) + "_" +
                                  std::get<1>(info.param);
                         });

class BackendsAgree : public ::testing::TestWithParam<GoldenScene> {};

TEST_P(BackendsAgree, BvhMatchesEmbree) {
  const GoldenScene& gs = GetParam();
  const ImageDiff d = diff_images(render_small(gs, "bvh"), render_small(gs, "embree"));
  EXPECT_GE(d.psnr_db, kMinPsnrBetweenBackends)
      << gs.name << ": RMSE " << d.rmse << ", max error " << d.max_error << " at (" << d.max_x
      << ", " << d.max_y << "), " << d.pixels_over << " pixels over";
  EXPECT_LE(d.pixels_over, d.pixels / 1000) << gs.name;
}

INSTANTIATE_TEST_SUITE_P(Scenes, BackendsAgree, ::testing::ValuesIn(kScenes),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace hprt
