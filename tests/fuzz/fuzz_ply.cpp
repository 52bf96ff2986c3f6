// libFuzzer target for the PLY reader: feeds the input to read_ply (in memory).
// hprt::InputError is the expected outcome for bad input; any other exception,
// crash or sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "io/mesh/ply_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)hprt::read_ply("fuzz.ply", std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const hprt::InputError&) {
  }
  return 0;
}
