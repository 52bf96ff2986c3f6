// Strict typed access to scene JSON (nlohmann::json): every read names the
// field by its JSON path ("camera.width", "lights[1].type") in errors, and an
// object reader rejects any key that was not asked for (typos never pass).
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/vec.h"

namespace hprt {

using Json = nlohmann::json;

// Parses `bytes`; a syntax error becomes one line InputError(file, "JSON
// parse error at line L, column C: ...").
Json parse_json(const std::string& file, std::string_view bytes);

// InputError(file, "field 'path': problem").
[[noreturn]] void throw_field_error(const std::string& file, const std::string& path,
                                    const std::string& problem);

// Field reads: the value must have the right type (and be finite for numbers),
// else a field error naming `path`.
double json_number(const std::string& file, const Json& j, const std::string& path);
float json_float(const std::string& file, const Json& j,
                 const std::string& path);  // finite as float
int64_t json_integer(const std::string& file, const Json& j, const std::string& path);
std::string json_string(const std::string& file, const Json& j, const std::string& path);
Vec3f json_vec3(const std::string& file, const Json& j, const std::string& path);
const Json& json_array(const std::string& file, const Json& j, const std::string& path);

// One JSON object being read: find() marks keys as known; finish() throws
// "unknown field 'path.key'" for the first key never asked for.
class JsonObject {
 public:
  JsonObject(const std::string& file, const Json& j, std::string path);
  const Json* find(std::string_view key);
  std::string field(std::string_view key) const;  // JSON path of a member
  const std::string& file() const { return file_; }
  void finish() const;

 private:
  const std::string& file_;
  const Json& json_;
  std::string path_;
  std::vector<std::string> used_;
};

}  // namespace hprt
