// Strict typed JSON field access for the scene reader (see scene_json.h).
#include "io/scene/scene_json.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_set>
#include <vector>

#include "core/error.h"

namespace hprt {

namespace {
constexpr int kMaxJsonDepth = 64;
}  // namespace

Json parse_json(const std::string& file, std::string_view bytes) {
  // A key twice in one object is an error (nlohmann keeps the last): one of
  // the two values would be ignored without a word. The keys of each open
  // object, innermost last.
  std::vector<std::unordered_set<std::string>> keys;
  const Json::parser_callback_t check = [&](int depth, Json::parse_event_t event, Json& parsed) {
    // No scene nests deeper than a few levels; a hostile file could nest
    // millions, each costing the parser and the key sets memory.
    if ((event == Json::parse_event_t::object_start || event == Json::parse_event_t::array_start) &&
        depth >= kMaxJsonDepth)
      throw InputError(file,
                       "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    if (event == Json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (event == Json::parse_event_t::object_end) {
      keys.pop_back();
    } else if (event == Json::parse_event_t::key) {
      const std::string& key = parsed.get_ref<const std::string&>();
      if (!keys.back().insert(key).second)
        throw InputError(file, "JSON object with the key '" + key + "' twice");
    }
    return true;
  };
  try {
    return Json::parse(bytes.begin(), bytes.end(), check);
  } catch (const Json::exception& e) {
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line L, column C: ..."
    std::string msg = e.what();
    const size_t close = msg.find("] ");
    if (msg.rfind("[json.exception.", 0) == 0 && close != std::string::npos)
      msg.erase(0, close + 2);
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    throw InputError(file, "JSON " + msg);
  }
}

void throw_field_error(const std::string& file, const std::string& path,
                       const std::string& problem) {
  throw InputError(file, "field '" + path + "': " + problem);
}

namespace {
std::string got(const Json& j) { return std::string("got ") + j.type_name(); }
}  // namespace

double json_number(const std::string& file, const Json& j, const std::string& path) {
  if (!j.is_number()) throw_field_error(file, path, "expected a number, " + got(j));
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw_field_error(file, path, "not a finite number");
  return v;
}

float json_float(const std::string& file, const Json& j, const std::string& path) {
  const double v = json_number(file, j, path);
  if (std::abs(v) > double(std::numeric_limits<float>::max()))
    throw_field_error(file, path, "out of single-precision range");
  return float(v);
}

int64_t json_integer(const std::string& file, const Json& j, const std::string& path) {
  if (j.is_number_unsigned()) {
    const uint64_t u = j.get<uint64_t>();
    if (u > uint64_t(std::numeric_limits<int64_t>::max()))
      throw_field_error(file, path, "too large");
    return int64_t(u);
  }
  if (j.is_number_integer()) return j.get<int64_t>();
  if (j.is_number_float()) {
    const double v = j.get<double>();
    if (std::isfinite(v) && v == std::floor(v) && std::abs(v) < 9.0e15) return int64_t(v);
    throw_field_error(file, path, "expected an integer, got " + j.dump());
  }
  throw_field_error(file, path, "expected an integer, " + got(j));
}

std::string json_string(const std::string& file, const Json& j, const std::string& path) {
  if (!j.is_string()) throw_field_error(file, path, "expected a string, " + got(j));
  return j.get<std::string>();
}

Vec3f json_vec3(const std::string& file, const Json& j, const std::string& path) {
  if (!j.is_array() || j.size() != 3)
    throw_field_error(
        file, path,
        "expected an array of 3 numbers, " +
            (j.is_array() ? "got " + std::to_string(j.size()) + " elements" : got(j)));
  Vec3f v;
  for (int k = 0; k < 3; ++k)
    v[k] = json_float(file, j[size_t(k)], path + "[" + std::to_string(k) + "]");
  return v;
}

const Json& json_array(const std::string& file, const Json& j, const std::string& path) {
  if (!j.is_array()) throw_field_error(file, path, "expected an array, " + got(j));
  return j;
}

JsonObject::JsonObject(const std::string& file, const Json& j, std::string path)
    : file_(file), json_(j), path_(std::move(path)) {
  if (!j.is_object()) {
    if (path_.empty())
      throw InputError(file, std::string("expected a JSON object, got ") + j.type_name());
    throw_field_error(file, path_, "expected an object, " + got(j));
  }
}

const Json* JsonObject::find(std::string_view key) {
  used_.emplace_back(key);
  const auto it = json_.find(key);
  return it == json_.end() ? nullptr : &*it;
}

std::string JsonObject::field(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void JsonObject::finish() const {
  for (const auto& [key, value] : json_.items())
    if (std::find(used_.begin(), used_.end(), key) == used_.end())
      throw InputError(file_, "unknown field '" + field(key) + "'");
}

}  // namespace hprt
