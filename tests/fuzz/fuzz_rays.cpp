// libFuzzer target for the .rays reader: read_rays only takes a path, so the
// input is written to a per-process temp file first. InputError is expected;
// anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "core/error.h"
#include "io/rays/ray_file.h"
#include "temp_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const TempFile file(".rays");
  const std::string& path = file.path;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    (void)hprt::read_rays(path);
  } catch (const hprt::InputError&) {
  }
  return 0;
}
