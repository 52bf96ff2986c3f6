// PSNR/RMSE/max error/pixels over a threshold via ImageBufAlgo::compare (the
// same numbers OpenImageIO's `idiff` prints), heat map from per-pixel maxima.
#include "image_diff.h"  // validators/ is on the include path of users only

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/error.h"

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

// A read-only view of an Image as an ImageBuf (OIIO wants a non-const pointer
// but compare() only reads).
OIIO::ImageBuf wrap(const Image& img) {
  OIIO::ImageSpec spec(img.width, img.height, img.channels, OIIO::TypeDesc::FLOAT);
  return OIIO::ImageBuf(spec, const_cast<float*>(img.pixels.data()));
}

Vec3f heat_ramp(float t) {  // t in [0, 1]: black, red, yellow, white
  t = std::clamp(t, 0.0f, 1.0f) * 3.0f;
  return {std::min(t, 1.0f), std::clamp(t - 1.0f, 0.0f, 1.0f), std::clamp(t - 2.0f, 0.0f, 1.0f)};
}

}  // namespace

ImageDiff diff_images(const Image& a, const Image& b, double threshold, const std::string& name_a,
                      const std::string& name_b) {
  check_same_size(a, b, name_a, name_b);
  const OIIO::ImageBuf ba = wrap(a), bb = wrap(b);
  OIIO::ROI roi = ba.roi();
  roi.chend = std::min(a.channels, b.channels);
  const OIIO::ImageBufAlgo::CompareResults r =
      OIIO::ImageBufAlgo::compare(ba, bb, float(threshold), float(threshold), 0.0f, 0.0f, roi);
  // r.error only says that some pixel exceeded the threshold (nfail > 0).
  ImageDiff d;
  d.width = a.width;
  d.height = a.height;
  d.channels = roi.chend;
  d.rmse = r.rms_error;
  d.mean_error = r.meanerror;
  d.max_error = r.maxerror;
  d.max_x = r.maxx;
  d.max_y = r.maxy;
  // OIIO's PSNR: 20 log10(peak / rmse), peak = max(1, largest |value|).
  d.psnr_db = r.rms_error > 0.0 ? r.PSNR : std::numeric_limits<double>::infinity();
  d.pixels_over = r.nfail;
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
