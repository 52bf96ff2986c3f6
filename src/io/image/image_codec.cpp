// Finds and loads the image codec module: the file HPRT_IMAGE_MODULE names
// if set, else beside the binary that holds this code (the build tree's src/,
// or an installed lib/hprt/ next to bin/), else where this build tree made it.
#include "io/image/image_codec.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "core/error.h"

namespace hprt {
namespace {

struct LoadedCodec {
  const ImageCodec* codec = nullptr;
  std::string error;
};

// The directory of the executable or shared object this code is linked into.
std::filesystem::path own_directory() {
  static const int anchor = 0;
  Dl_info info{};
  if (dladdr(&anchor, &info) == 0 || !info.dli_fname) return {};
  return std::filesystem::path(info.dli_fname).parent_path();
}

LoadedCodec load_codec() {
  std::vector<std::filesystem::path> candidates;
  if (const char* env = std::getenv("HPRT_IMAGE_MODULE"); env && *env) {
    candidates.emplace_back(env);
  } else if (const std::filesystem::path dir = own_directory(); !dir.empty()) {
    candidates.push_back(dir / HPRT_IMAGE_MODULE_NAME);
    candidates.push_back(dir / "hprt" / HPRT_IMAGE_MODULE_NAME);  // beside an installed libhprt.so
    candidates.push_back(dir / ".." / HPRT_IMAGE_MODULE_LIBDIR / "hprt" / HPRT_IMAGE_MODULE_NAME);
    candidates.emplace_back(HPRT_IMAGE_MODULE_BUILD_PATH);
  } else {
    candidates.emplace_back(HPRT_IMAGE_MODULE_BUILD_PATH);
  }
  std::string error;
  for (const std::filesystem::path& path : candidates) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) continue;
    void* module = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (!module) {
      const char* e = dlerror();
      error = e ? e : path.string() + ": cannot be loaded";
      continue;
    }
    using Entry = const ImageCodec* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(module, "hprt_image_codec"));
    const ImageCodec* codec = entry ? entry() : nullptr;
    if (!codec || codec->abi != kImageCodecAbi) {
      error = path.string() + " is not an image codec of this hprt";
      continue;
    }
    return {codec, ""};
  }
  if (error.empty()) {
    error = "no ";  // appended piecewise: g++ 12 warns falsely (-Wrestrict) on a + chain
    error += HPRT_IMAGE_MODULE_NAME;
    error += " at";
    for (const std::filesystem::path& path : candidates) error += " " + path.string();
  }
  return {nullptr, error};
}

}  // namespace

const ImageCodec& image_codec(const std::string& what) {
  static const LoadedCodec loaded = load_codec();
  if (!loaded.codec) throw InputError(what, "image support unavailable: " + loaded.error);
  return *loaded.codec;
}

}  // namespace hprt
