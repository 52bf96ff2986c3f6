// The image codec over OpenImageIO, built as the module libhprt_oiio.so (see
// io/image/image_codec.h). The writer is chosen from the target name's extension
// (ImageOutput::create) and then opened on the file to write, so a temporary
// name's suffix does not matter.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "io/image/image_codec.h"

namespace hprt {
namespace {

bool has_writer(const std::string& path) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) OIIO::geterror();  // clear OIIO's message ("could not find a format writer ...")
  return bool(out);
}

std::string write(const std::string& format_path, const std::string& file, int width, int height,
                  bool as_float, const void* pixels) {
  auto out = OIIO::ImageOutput::create(format_path);
  if (!out) {
    OIIO::geterror();
    return "no image writer for this file name";
  }
  OIIO::ImageSpec spec(width, height, 3, as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", as_float ? "linear" : "sRGB");
  spec.attribute("Software", "hprt");
  if (!out->open(file, spec)) return out->geterror();
  if (!out->write_image(as_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8, pixels)) {
    const std::string err = out->geterror();
    out->close();
    return "cannot write image: " + err;
  }
  if (!out->close()) return "cannot write image: " + out->geterror();
  return "";
}

std::string read(const std::string& path, Image& img) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string err = OIIO::geterror();
    return err.empty() ? "cannot read image" : err;
  }
  const OIIO::ImageSpec& spec = in->spec();
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  if (img.width <= 0 || img.height <= 0 || img.channels <= 0) return "image has no pixels";
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.pixels.data()))
    return "cannot read image: " + in->geterror();
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
