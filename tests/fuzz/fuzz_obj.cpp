// libFuzzer target for the OBJ reader: feeds the input to read_obj (in memory).
// The name sits in a directory that does not exist, so `mtllib` lines resolve
// to missing files (not an error). InputError is expected; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "io/mesh/obj_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)hprt::read_obj("/nonexistent-hprt-fuzz/fuzz.obj",
                         std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const hprt::InputError&) {
  }
  return 0;
}
