// OpenImageIO reading and writing. The writer is chosen from the target
// name's extension (ImageOutput::create(path)) and then opened on the
// AtomicFile's temporary name, so the temporary name's suffix does not matter.
#include "io/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "core/error.h"
#include "io/atomic_file.h"

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

OIIO::ImageOutput::unique_ptr create_writer(const std::string& path) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) {
    OIIO::geterror();  // clear OIIO's message ("could not find a format writer ...")
    const std::string ext = lower_extension(path);
    throw InputError(path, ext.empty() ? "no file extension to choose an image format from"
                                       : "unknown image format '." + ext + "'");
  }
  return out;
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
  create_writer(path);
  AtomicFile probe(path);  // throws when the directory is missing or unwritable
}

void write_image(const std::string& path, int width, int height, std::span<const Vec3f> rgb,
                 PixelEncoding encoding) {
  if (width <= 0 || height <= 0) throw InputError(path, "image size must be positive");
  if (rgb.size() != size_t(width) * size_t(height))
    throw InputError(path, "pixel count does not match the image size");
  auto out = create_writer(path);
  AtomicFile file(path);
  const bool as_float = is_float_image_format(path);
  OIIO::ImageSpec spec(width, height, 3, as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", as_float ? "linear" : "sRGB");
  spec.attribute("Software", "hprt");
  if (!out->open(file.temp_path(), spec)) throw InputError(path, out->geterror());
  bool ok;
  if (as_float) {
    ok = out->write_image(OIIO::TypeDesc::FLOAT, rgb.data());
  } else {
    std::vector<uint8_t> bytes(rgb.size() * 3);
    for (size_t i = 0; i < rgb.size(); ++i)
      for (int c = 0; c < 3; ++c)
        bytes[i * 3 + size_t(c)] =
            encoding == PixelEncoding::kLinear ? linear_to_srgb8(rgb[i][c]) : to_byte(rgb[i][c]);
    ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  }
  if (!ok) {
    const std::string err = out->geterror();
    out->close();
    throw InputError(path, "cannot write image: " + err);
  }
  if (!out->close()) throw InputError(path, "cannot write image: " + out->geterror());
  file.commit();
}

Image read_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string err = OIIO::geterror();
    if (err.empty()) err = "cannot read image";
    throw InputError(path, err);
  }
  const OIIO::ImageSpec& spec = in->spec();
  Image img;
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  if (img.width <= 0 || img.height <= 0 || img.channels <= 0)
    throw InputError(path, "image has no pixels");
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.pixels.data()))
    throw InputError(path, "cannot read image: " + in->geterror());
  in->close();
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
