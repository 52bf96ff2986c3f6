// Image files through OpenImageIO, format chosen by the file extension.
// 8-bit formats (PNG, JPEG, ...) store sRGB-encoded values of the linear
// render; float formats (EXR, HDR, PFM) store the linear values themselves.
// Writes are atomic (AtomicFile). Errors throw InputError("path: problem").
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/vec.h"

namespace hprt {

// What the pixel values passed to write_image mean.
enum class PixelEncoding {
  kLinear,   // linear radiance: sRGB-encoded for 8-bit formats
  kDisplay,  // already display values in [0, 1] (e.g. a diff heat map): stored as is
};

// An image as read: `channels` floats per pixel, row-major, row 0 at the top.
// 8-bit files read as code/255 (no decoding of the sRGB curve).
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;
  float at(int x, int y, int c) const {
    return pixels[(size_t(y) * size_t(width) + size_t(x)) * size_t(channels) + size_t(c)];
  }
};

// Throws InputError when `path` cannot be written: no OpenImageIO writer for
// its extension, or a missing or unwritable directory. Cheap; call it before
// long work so a bad -o fails at once and leaves nothing behind.
void check_image_output(const std::string& path);

// Whether write_image stores floats (EXR, HDR, PFM) or 8-bit sRGB for `path`.
bool is_float_image_format(const std::string& path);

// Writes width x height RGB pixels to `path`.
void write_image(const std::string& path, int width, int height, std::span<const Vec3f> rgb,
                 PixelEncoding encoding = PixelEncoding::kLinear);

// Reads any format OpenImageIO knows, converted to float.
Image read_image(const std::string& path);

// The sRGB transfer function (IEC 61966-2-1) and its 8-bit quantisation.
float linear_to_srgb(float linear);
uint8_t linear_to_srgb8(float linear);

// What an 8-bit file written from `linear` reads back as (code/255 per
// channel): lets a render be compared with a PNG without a file.
Image encode_srgb8(int width, int height, std::span<const Vec3f> linear);

}  // namespace hprt
