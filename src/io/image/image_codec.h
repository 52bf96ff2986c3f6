// The image codec: what image_io and image_diff need of OpenImageIO, as a
// table of functions in a module (src/image_oiio, libhprt_oiio.so) that is
// loaded on first use. OpenImageIO brings about 250 shared libraries whose
// loading and relocation cost ~0.4 s of every process start; loaded on
// demand, only commands that read or write images pay it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/image/image_io.h"

namespace hprt {

// Per-channel comparison of two images, OpenImageIO's compare() (`idiff`).
struct ImageCompareResult {
  double mean_error = 0.0;
  double rms_error = 0.0;
  double psnr = 0.0;  // 20 log10(peak / rmse), peak = max(1, largest |value|)
  double max_error = 0.0;
  int max_x = 0, max_y = 0;
  uint64_t pixels_over = 0;  // pixels with some channel |A - B| > threshold
};

inline constexpr int kImageCodecAbi = 2;

// Each function returns "" on success, else the problem (without the path).
struct ImageCodec {
  int abi = kImageCodecAbi;
  // Whether a writer exists for `path`'s extension.
  bool (*has_writer)(const std::string& path);
  // Encodes width x height x 3 pixels (float, or uint8 when !as_float) into
  // `bytes`, in the format `format_path`'s extension names.
  std::string (*write)(const std::string& format_path, std::vector<unsigned char>& bytes, int width,
                       int height, bool as_float, const void* pixels);
  // Reads every channel of `path`'s first subimage as float.
  std::string (*read)(const std::string& path, Image& image);
  // Compares the first `channels` channels of two images of the same size.
  std::string (*compare)(const Image& a, const Image& b, int channels, float threshold,
                         ImageCompareResult& result);
};

// The loaded codec; loads it on the first call (thread-safe): the file the
// environment variable HPRT_IMAGE_MODULE names if set, else the module beside
// this binary, in ../lib/hprt/ from it, or in this build tree. Throws
// InputError(what, "image support unavailable: ...") when the module cannot
// be loaded.
const ImageCodec& image_codec(const std::string& what);

}  // namespace hprt

// The module's one exported symbol.
extern "C" const hprt::ImageCodec* hprt_image_codec();
