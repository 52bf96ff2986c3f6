// The image codec over OpenImageIO, built as the module libhprt_oiio.so (see
// io/image/image_codec.h). The writer is chosen from the target name's
// extension (ImageOutput::create) and encodes into memory; the caller writes
// the bytes.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "core/camera.h"
#include "io/image/image_codec.h"

namespace hprt {
namespace {

// Writers that can encode into memory (every format hprt names does).
bool has_writer(const std::string& path) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) OIIO::geterror();  // clear OIIO's message ("could not find a format writer ...")
  return out && out->supports("ioproxy");
}

// Encoded in memory, so that the caller writes the file with its own checked
// writer: OIIO's writers reported success on a full disk (a 0-byte PNG), and
// libjpeg's called exit(1), leaving the temporary file behind.
std::string write(const std::string& format_path, std::vector<unsigned char>& bytes, int width,
                  int height, bool as_float, const void* pixels) {
  OIIO::Filesystem::IOVecOutput memory(bytes);
  auto out = OIIO::ImageOutput::create(format_path, &memory);
  if (!out || !out->supports("ioproxy")) {
    OIIO::geterror();
    return "no image writer for this file name";
  }
  OIIO::ImageSpec spec(width, height, 3, as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", as_float ? "linear" : "sRGB");
  spec.attribute("Software", "hprt");
  if (!out->open(format_path, spec)) return out->geterror();
  if (!out->write_image(as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8, pixels)) {
    const std::string err = out->geterror();
    out->close();
    return "cannot write image: " + err;
  }
  if (!out->close()) return "cannot write image: " + out->geterror();
  return "";
}

// libpng (and libjpeg) print their errors to stderr themselves, besides the
// message OpenImageIO hands back: while a file is decoded, stderr goes to
// /dev/null, so the caller's one line is the only one. (The image commands
// decode on one thread; nothing else prints meanwhile.)
class QuietStderr {
 public:
  QuietStderr() : saved_(::dup(STDERR_FILENO)) {
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_;
};

// What a PNG's chunk headers say: bits per pixel (IHDR's bit depth times its
// colour type's samples; 0 when there is no valid IHDR) and the bytes of its
// IDAT chunks. Only the chunk headers (and IHDR) are read; a file cut short
// ends the walk (OIIO then says what is wrong).
struct PngLayout {
  unsigned bits_per_pixel = 0;
  uint64_t idat_bytes = 0;
};
PngLayout read_png_layout(const std::string& path) {
  PngLayout out;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return out;
  const auto be32 = [](const unsigned char* b) {
    return uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | uint32_t(b[3]);
  };
  // A chunk's IDAT bytes count only as far as the file holds them (its
  // length field may lie too).
  long size = 0;
  if (std::fseek(f, 0, SEEK_END) == 0) size = std::ftell(f);
  std::rewind(f);
  unsigned char head[8];
  if (size > 0 && std::fread(head, 1, 8, f) == 8)  // the signature
    while (std::fread(head, 1, 8, f) == 8) {
      const uint32_t length = be32(head);
      const std::string_view type(reinterpret_cast<const char*>(head + 4), 4);
      long skip = long(length) + 4;  // data and CRC
      if (type == "IHDR" && length == 13) {
        unsigned char ihdr[13];
        if (std::fread(ihdr, 1, 13, f) != 13) break;
        skip -= 13;
        const unsigned depth = ihdr[8], colour = ihdr[9];
        const unsigned samples = colour == 0 || colour == 3 ? 1
                                 : colour == 2              ? 3
                                 : colour == 4              ? 2
                                 : colour == 6              ? 4
                                                            : 0;
        out.bits_per_pixel = depth <= 16 ? depth * samples : 0;
      } else if (type == "IDAT") {
        const long here = std::ftell(f);
        out.idat_bytes += std::min<uint64_t>(length, uint64_t(std::max(0L, size - here)));
      } else if (type == "IEND") {
        break;
      }
      if (std::fseek(f, skip, SEEK_CUR) != 0) break;
    }
  std::fclose(f);
  return out;
}

std::string read(const std::string& path, Image& img) {
  const QuietStderr quiet;
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string err = OIIO::geterror();
    return err.empty() ? "cannot read image" : err;
  }
  const OIIO::ImageSpec& spec = in->spec();
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  if (img.width <= 0 || img.height <= 0 || img.channels <= 0 || spec.depth > 1)
    return "image has no pixels";
  const long long pixels = static_cast<long long>(img.width) * img.height;
  if (pixels > kMaxCameraPixels)
    return "image of " + std::to_string(img.width) + "x" + std::to_string(img.height) +
           " pixels, more than hprt renders (" + std::to_string(kMaxCameraPixels) + ")";
  // OIIO decodes an interlaced PNG whole on its first row, so its header's
  // size is allocated before any data is read. But deflate expands at most
  // 1032:1: a header that claims more pixel bytes than that of its IDAT
  // data is a lie, told before the allocation.
  if (in->format_name() == std::string_view("png")) {
    const PngLayout png = read_png_layout(path);
    const uint64_t need = (uint64_t(pixels) * png.bits_per_pixel + 7) / 8;
    if (png.bits_per_pixel > 0 && need > 1032 * (png.idat_bytes + 64))
      return "PNG header claims " + std::to_string(img.width) + "x" + std::to_string(img.height) +
             " pixels of " + std::to_string(png.bits_per_pixel) + " bits, more than its " +
             std::to_string(png.idat_bytes) + " bytes of image data can hold";
  }
  const size_t row = size_t(img.width) * size_t(img.channels);
  // Strips of about 1 MiB (whole rows of tiles in a tiled file), the buffer
  // growing as the rows arrive: a header that claims more pixels than the
  // file holds fails at its first missing row, before its size is allocated.
  const bool tiled = spec.tile_width > 0;
  const int unit = tiled ? std::max(1, spec.tile_height) : 1;
  const int strip = unit * int(std::max<size_t>(1, (size_t{1} << 18) / (row * size_t(unit))));
  for (int y = 0; y < img.height; y += strip) {
    const int end = std::min(img.height, y + strip);
    const size_t need = row * size_t(end);
    if (need > img.pixels.capacity())
      img.pixels.reserve(
          std::max(need, std::min(2 * img.pixels.capacity(), row * size_t(img.height))));
    img.pixels.resize(need);
    float* dst = img.pixels.data() + row * size_t(y);
    const bool ok =
        tiled ? in->read_tiles(0, 0, spec.x, spec.x + spec.width, spec.y + y, spec.y + end, spec.z,
                               spec.z + 1, 0, img.channels, OIIO::TypeDesc::FLOAT, dst)
              : in->read_scanlines(0, 0, spec.y + y, spec.y + end, 0, 0, img.channels,
                                   OIIO::TypeDesc::FLOAT, dst);
    if (!ok) return "cannot read image: " + in->geterror();
  }
  in->close();
  return "";
}

// A read-only view of an Image as an ImageBuf (OIIO wants a non-const pointer
// but compare() only reads).
OIIO::ImageBuf wrap(const Image& img) {
  OIIO::ImageSpec spec(img.width, img.height, img.channels, OIIO::TypeDesc::FLOAT);
  return OIIO::ImageBuf(spec, const_cast<float*>(img.pixels.data()));
}

std::string compare(const Image& a, const Image& b, int channels, float threshold,
                    ImageCompareResult& result) {
  const OIIO::ImageBuf ba = wrap(a), bb = wrap(b);
  OIIO::ROI roi = ba.roi();
  roi.chend = channels;
  const OIIO::ImageBufAlgo::CompareResults r =
      OIIO::ImageBufAlgo::compare(ba, bb, threshold, threshold, 0.0f, 0.0f, roi);
  // r.error only says that some pixel exceeded the threshold (nfail > 0).
  result.mean_error = r.meanerror;
  result.rms_error = r.rms_error;
  result.psnr = r.PSNR;
  result.max_error = r.maxerror;
  result.max_x = r.maxx;
  result.max_y = r.maxy;
  result.pixels_over = uint64_t(r.nfail);
  return "";
}

constexpr ImageCodec kCodec{kImageCodecAbi, has_writer, write, read, compare};

}  // namespace
}  // namespace hprt

extern "C" __attribute__((visibility("default"))) const hprt::ImageCodec* hprt_image_codec() {
  return &hprt::kCodec;
}
