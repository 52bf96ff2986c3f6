// Image comparison: identical images, known differences (RMSE, PSNR, max
// error, pixels over), size mismatch, and the image files round trip.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "io/image/image_io.h"
#include "validators/image_diff.h"

namespace hprt {
namespace {

Image flat(int w, int h, float v) {
  Image img;
  img.width = w;
  img.height = h;
  img.channels = 3;
  img.pixels.assign(size_t(w) * size_t(h) * 3, v);
  return img;
}

std::string temp_dir() {
  const auto d = std::filesystem::temp_directory_path() /
                 ("hprt_test_image_diff_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d.string();
}

TEST(ImageDiff, IdenticalImagesHaveInfinitePsnr) {
  Image a = flat(16, 8, 0.25f);
  a.pixels[5] = 0.9f;
  const ImageDiff d = diff_images(a, a);
  EXPECT_TRUE(std::isinf(d.psnr_db));
  EXPECT_EQ(d.rmse, 0.0);
  EXPECT_EQ(d.max_error, 0.0);
  EXPECT_EQ(d.pixels_over, 0u);
  EXPECT_EQ(d.pixels, 128u);
}

TEST(ImageDiff, KnownDifferencesGiveKnownNumbers) {
  // 10 x 10 pixels, 3 channels: pixel (2,3) differs by 0.5 in one channel and
  // pixel (7,1) by 0.005 in all three (under the 0.01 threshold).
  const Image a = flat(10, 10, 0.2f);
  Image b = a;
  b.pixels[(3 * 10 + 2) * 3 + 1] += 0.5f;
  for (int c = 0; c < 3; ++c) b.pixels[(1 * 10 + 7) * 3 + c] += 0.005f;
  const ImageDiff d = diff_images(a, b, 0.01f);
  const double expected_mse = (0.5 * 0.5 + 3 * 0.005 * 0.005) / 300.0;
  EXPECT_NEAR(d.rmse, std::sqrt(expected_mse), 1e-6);
  EXPECT_NEAR(d.psnr_db, 20.0 * std::log10(1.0 / std::sqrt(expected_mse)), 1e-3);
  EXPECT_NEAR(d.max_error, 0.5, 1e-6);
  EXPECT_EQ(d.max_x, 2);
  EXPECT_EQ(d.max_y, 3);
  EXPECT_EQ(d.pixels_over, 1u);
  // A threshold below 0.005 counts both pixels.
  EXPECT_EQ(diff_images(a, b, 0.004f).pixels_over, 2u);
}

TEST(ImageDiff, DifferentSizesAreAnInputError) {
  EXPECT_THROW(diff_images(flat(10, 10, 0.0f), flat(10, 11, 0.0f)), InputError);
}

TEST(ImageDiff, PngRoundTripMatchesInMemoryEncoding) {
  const std::string dir = temp_dir();
  const int w = 7, h = 5;
  std::vector<Vec3f> linear(size_t(w * h));
  for (int i = 0; i < w * h; ++i) linear[size_t(i)] = Vec3f(i / 35.0f, 0.5f, 1.5f);
  const std::string png = dir + "/a.png";
  write_image(png, w, h, linear);
  const Image read = read_image(png);
  ASSERT_EQ(read.width, w);
  ASSERT_EQ(read.height, h);
  ASSERT_EQ(read.channels, 3);
  const ImageDiff d = diff_images(read, encode_srgb8(w, h, linear));
  EXPECT_EQ(d.rmse, 0.0);
  EXPECT_NEAR(read.at(0, 0, 1), linear_to_srgb8(0.5f) / 255.0f, 1e-7f);
  EXPECT_EQ(read.at(3, 2, 2), 1.0f);  // clamped

  // EXR keeps linear floats.
  const std::string exr = dir + "/a.exr";
  write_image(exr, w, h, linear);
  const Image f = read_image(exr);
  EXPECT_FLOAT_EQ(f.at(4, 1, 0), linear[size_t(1 * w + 4)].x);
  EXPECT_FLOAT_EQ(f.at(4, 1, 2), 1.5f);

  // Heat map: identical images give black; no temporary files remain.
  write_diff_heatmap(dir + "/d.png", read, read);
  const Image heat = read_image(dir + "/d.png");
  for (float v : heat.pixels) EXPECT_EQ(v, 0.0f);
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 3u);
  std::filesystem::remove_all(dir);
}

TEST(ImageDiff, TallScanlineAndTiledImagesReadWholeInStrips) {
  // Read a strip of rows (or of tile rows) at a time: an image of many
  // strips, and the same tiled with its data window moved, read back exactly.
  const std::string dir = temp_dir();
  const int w = 300, h = 2000;  // rows of 900 floats: strips of 291 rows
  std::vector<Vec3f> linear(size_t(w) * h);
  for (size_t i = 0; i < linear.size(); ++i)
    linear[i] = Vec3f(float(i % 977) / 977.0f, float(i / w) / h, 0.25f);
  const std::string exr = dir + "/tall.exr";
  write_image(exr, w, h, linear);
  const auto expect_same = [&](const Image& img) {
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    for (int y = 0; y < h; y += 97)
      for (int x = 0; x < w; x += 13)
        ASSERT_EQ(img.at(x, y, 0), linear[size_t(y) * w + size_t(x)].x) << x << "," << y;
    EXPECT_EQ(img.at(w - 1, h - 1, 1), linear.back().y);
  };
  expect_same(read_image(exr));
  if (std::system("command -v oiiotool >/dev/null 2>&1") == 0) {
    const std::string tiled = dir + "/tiled.exr";
    ASSERT_EQ(std::system(
                  ("oiiotool '" + exr + "' --origin +3+5 --tile 64 32 -o '" + tiled + "'").c_str()),
              0);
    expect_same(read_image(tiled));
  }
  std::filesystem::remove_all(dir);
}

TEST(ImageDiff, UnknownFormatAndMissingFileAreInputErrors) {
  const std::string dir = temp_dir();
  const std::vector<Vec3f> px(4, Vec3f(0.5f));
  EXPECT_THROW(write_image(dir + "/a.notaformat", 2, 2, px), InputError);
  EXPECT_THROW(check_image_output(dir + "/no/such/dir/a.png"), InputError);
  EXPECT_THROW(read_image(dir + "/missing.png"), InputError);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hprt
