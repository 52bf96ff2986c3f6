// libFuzzer target for scene JSON: load_scene only takes a path, so the input
// is written to a per-process temp .json file. load_scene accepts "generate"
// blocks of up to 200M triangles (kMaxGenerateTriangles), a legitimate request
// that would only exhaust the fuzzer's memory, so inputs asking for more than
// kMaxFuzzTris anywhere are skipped here.
// InputError is expected; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/scene/scene_reader.h"
#include "temp_file.h"

namespace {

constexpr double kMaxFuzzTris = 100000;

// True when some "tris" member anywhere in `j` is a number above the cap.
bool asks_for_huge_mesh(const nlohmann::json& j) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      if (key == "tris" && value.is_number() && value.get<double>() > kMaxFuzzTris) return true;
      if (asks_for_huge_mesh(value)) return true;
    }
  } else if (j.is_array()) {
    for (const auto& value : j)
      if (asks_for_huge_mesh(value)) return true;
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // Vet the parsed document, not the text: keys may be spelt with \u escapes.
  // Unparsable input goes on to load_scene, which must reject it.
  const auto j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_discarded() && asks_for_huge_mesh(j)) return 0;
  static const TempFile file(".json");
  const std::string& path = file.path;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(text.data(), std::streamsize(size));
  }
  try {
    (void)hprt::load_scene(path);
  } catch (const hprt::InputError&) {
  }
  return 0;
}
