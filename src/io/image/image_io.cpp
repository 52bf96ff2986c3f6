// Image reading and writing through the image codec (OpenImageIO, loaded on
// first use: image_codec.h). The format is chosen from the target name's
// extension; the codec encodes into memory and write_file_atomic writes it.
#include "io/image/image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "io/files/atomic_file.h"
#include "io/image/image_codec.h"

namespace hprt {
namespace {

std::string lower_extension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void require_writer(const std::string& path) {
  if (image_codec(path).has_writer(path)) return;
  const std::string ext = lower_extension(path);
  throw InputError(path, ext.empty() ? "no file extension to choose an image format from"
                                     : "unknown image format '." + ext + "'");
}

uint8_t to_byte(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 1.0f) return 255;
  return uint8_t(v * 255.0f + 0.5f);
}

}  // namespace

float linear_to_srgb(float c) {
  if (!(c > 0.0f)) return 0.0f;
  if (c >= 1.0f) return 1.0f;
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

uint8_t linear_to_srgb8(float linear) { return to_byte(linear_to_srgb(linear)); }

bool is_float_image_format(const std::string& path) {
  const std::string ext = lower_extension(path);
  return ext == "exr" || ext == "hdr" || ext == "pfm";
}

void check_image_output(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, "is a directory: name a file to write");
  require_writer(path);
  AtomicFile probe(path);  // throws when the directory is missing or unwritable
}

void write_image(const std::string& path, int width, int height, std::span<const Vec3f> rgb,
                 PixelEncoding encoding) {
  if (width <= 0 || height <= 0) throw InputError(path, "image size must be positive");
  if (rgb.size() != size_t(width) * size_t(height))
    throw InputError(path, "pixel count does not match the image size");
  require_writer(path);
  const bool as_float = is_float_image_format(path);
  std::vector<uint8_t> bytes;
  if (!as_float) {
    bytes.resize(rgb.size() * 3);
    for (size_t i = 0; i < rgb.size(); ++i)
      for (int c = 0; c < 3; ++c)
        bytes[i * 3 + size_t(c)] =
            encoding == PixelEncoding::kLinear ? linear_to_srgb8(rgb[i][c]) : to_byte(rgb[i][c]);
  }
  std::vector<unsigned char> encoded;
  const std::string err =
      image_codec(path).write(path, encoded, width, height, as_float,
                              as_float ? static_cast<const void*>(rgb.data()) : bytes.data());
  if (!err.empty()) throw InputError(path, err);
  // (OIIO's JPEG 2000 writer, for one, "succeeds" into memory with no bytes.)
  if (encoded.empty()) throw InputError(path, "the image writer produced no data");
  write_file_atomic(path, encoded.data(), encoded.size());  // whole or not at all, disk full too
}

Image read_image(const std::string& path) {
  // OpenImageIO opens the file itself: a FIFO would block it, a device feed it forever.
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError(path, "not a regular file");
  Image img;
  const std::string err = image_codec(path).read(path, img);
  if (!err.empty()) throw InputError(path, err);
  return img;
}

Image encode_srgb8(int width, int height, std::span<const Vec3f> linear) {
  Image img;
  img.width = width;
  img.height = height;
  img.channels = 3;
  img.pixels.resize(linear.size() * 3);
  for (size_t i = 0; i < linear.size(); ++i)
    for (int c = 0; c < 3; ++c)
      img.pixels[i * 3 + size_t(c)] = float(linear_to_srgb8(linear[i][c])) * (1.0f / 255.0f);
  return img;
}

}  // namespace hprt
