// Image comparison through OpenImageIO's compare() (io/image/image_codec.h): PSNR, RMSE,
// max error, pixels over a per-channel threshold, and a diff heat map.
// Values compared are the stored ones (8-bit files as code/255, so an 8-bit
// step is 1/255 ~ 0.0039; float files as stored).
#pragma once

#include <cstdint>
#include <string>

#include "io/image/image_io.h"

namespace hprt {

// Default per-channel |A - B| above which a pixel counts as "over": 0.01,
// i.e. more than 2 steps of an 8-bit file (rounding of equal renders gives at
// most 1 step).
inline constexpr double kDefaultDiffThreshold = 0.01;

struct ImageDiff {
  int width = 0;
  int height = 0;
  int channels = 0;      // channels compared (the fewer of the two images)
  double psnr_db = 0.0;  // 20 log10(1 / rmse); +inf for identical images
  double rmse = 0.0;     // over every compared channel of every pixel
  double mean_error = 0.0;
  double max_error = 0.0;  // largest |A - B| of any channel
  int max_x = 0, max_y = 0;
  uint64_t pixels_over = 0;  // pixels with some channel |A - B| > threshold
  uint64_t pixels = 0;
};

// Throws InputError when the sizes differ (the message names both sizes).
ImageDiff diff_images(const Image& a, const Image& b, double threshold = kDefaultDiffThreshold,
                      const std::string& name_a = "A", const std::string& name_b = "B");
ImageDiff diff_image_files(const std::string& path_a, const std::string& path_b,
                           double threshold = kDefaultDiffThreshold);

// Heat map of max-channel |A - B| per pixel, scaled so the largest difference
// is white: black -> red -> yellow -> white. Identical images give black.
// Written through write_image (any format by extension, atomically).
void write_diff_heatmap(const std::string& path, const Image& a, const Image& b);

}  // namespace hprt
