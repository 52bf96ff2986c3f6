// PSNR/RMSE/max error/pixels over a threshold via OpenImageIO's compare()
// (the image codec; the same numbers `idiff` prints), heat map from
// per-pixel maxima.
#include "validators/image_diff.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/error.h"
#include "io/image/image_codec.h"

namespace hprt {
namespace {

void check_same_size(const Image& a, const Image& b, const std::string& name_a,
                     const std::string& name_b) {
  if (a.width != b.width || a.height != b.height)
    throw InputError(name_a + " and " + name_b, "image sizes differ: " + std::to_string(a.width) +
                                                    "x" + std::to_string(a.height) + " vs " +
                                                    std::to_string(b.width) + "x" +
                                                    std::to_string(b.height));
}

Vec3f heat_ramp(float t) {  // t in [0, 1]: black, red, yellow, white
  t = std::clamp(t, 0.0f, 1.0f) * 3.0f;
  return {std::min(t, 1.0f), std::clamp(t - 1.0f, 0.0f, 1.0f), std::clamp(t - 2.0f, 0.0f, 1.0f)};
}

}  // namespace

ImageDiff diff_images(const Image& a, const Image& b, double threshold, const std::string& name_a,
                      const std::string& name_b) {
  check_same_size(a, b, name_a, name_b);
  const std::string what = name_a + " and " + name_b;
  const int channels = std::min(a.channels, b.channels);
  ImageCompareResult r;
  const std::string err = image_codec(what).compare(a, b, channels, float(threshold), r);
  if (!err.empty()) throw InputError(what, err);
  ImageDiff d;
  d.width = a.width;
  d.height = a.height;
  d.channels = channels;
  d.rmse = r.rms_error;
  d.mean_error = r.mean_error;
  d.max_error = r.max_error;
  d.max_x = r.max_x;
  d.max_y = r.max_y;
  d.psnr_db = r.rms_error > 0.0 ? r.psnr : std::numeric_limits<double>::infinity();
  d.pixels_over = r.pixels_over;
  d.pixels = uint64_t(a.width) * uint64_t(a.height);
  return d;
}

ImageDiff diff_image_files(const std::string& path_a, const std::string& path_b, double threshold) {
  return diff_images(read_image(path_a), read_image(path_b), threshold, path_a, path_b);
}

void write_diff_heatmap(const std::string& path, const Image& a, const Image& b) {
  check_same_size(a, b, "A", "B");
  const int channels = std::min(a.channels, b.channels);
  const size_t n = size_t(a.width) * size_t(a.height);
  std::vector<float> diff(n, 0.0f);
  float max_diff = 0.0f;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < channels; ++c)
      diff[i] = std::max(diff[i], std::fabs(a.pixels[i * size_t(a.channels) + size_t(c)] -
                                            b.pixels[i * size_t(b.channels) + size_t(c)]));
    max_diff = std::max(max_diff, diff[i]);
  }
  std::vector<Vec3f> rgb(n);
  for (size_t i = 0; i < n; ++i) rgb[i] = heat_ramp(max_diff > 0.0f ? diff[i] / max_diff : 0.0f);
  write_image(path, a.width, a.height, rgb, PixelEncoding::kDisplay);
}

}  // namespace hprt
