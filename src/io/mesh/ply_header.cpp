// PLY header parsing: line by line up to end_header; the data section is read
// by ply_reader.cpp.
#include "io/mesh/ply_header.h"

#include <charconv>

#include "core/error.h"

namespace hprt {
namespace {

struct TypeName {
  std::string_view name;
  PlyType type;
};
constexpr TypeName kTypeNames[] = {
    {"char", PlyType::kInt8},       {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
    {"uint8", PlyType::kUint8},     {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
    {"ushort", PlyType::kUint16},   {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
    {"int32", PlyType::kInt32},     {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
    {"float", PlyType::kFloat32},   {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
    {"float64", PlyType::kFloat64},
};

bool parse_type(std::string_view s, PlyType* out) {
  for (const TypeName& t : kTypeNames)
    if (t.name == s) {
      *out = t.type;
      return true;
    }
  return false;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// A printable header: anything below 0x20 but tab is binary, i.e. not PLY.
bool printable(std::string_view line) {
  for (char c : line)
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t') return false;
  return true;
}

}  // namespace

size_t ply_type_size(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool ply_type_is_integer(PlyType t) { return t != PlyType::kFloat32 && t != PlyType::kFloat64; }

bool PlyElement::has_list() const {
  for (const PlyProperty& p : properties)
    if (p.is_list) return true;
  return false;
}

size_t PlyElement::min_binary_record_bytes() const {
  size_t n = 0;
  for (const PlyProperty& p : properties) n += ply_type_size(p.is_list ? p.count_type : p.type);
  return n;
}

int PlyElement::find(std::string_view wanted) const {
  for (size_t i = 0; i < properties.size(); ++i)
    if (properties[i].name == wanted) return static_cast<int>(i);
  return -1;
}

PlyHeader parse_ply_header(const std::string& path, std::string_view bytes) {
  PlyHeader h;
  size_t pos = 0;
  size_t line_no = 0;
  bool have_format = false;
  // Next line without its terminator; false at the end of the data.
  auto next_line = [&](std::string_view* line) {
    if (pos >= bytes.size()) return false;
    const size_t nl = bytes.find('\n', pos);
    const size_t end = nl == std::string_view::npos ? bytes.size() : nl;
    *line = bytes.substr(pos, end - pos);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    pos = nl == std::string_view::npos ? bytes.size() : nl + 1;
    ++line_no;
    return true;
  };
  auto fail = [&](const std::string& problem) -> InputError {
    return InputError(path, "PLY header line " + std::to_string(line_no) + ": " + problem);
  };

  std::string_view line;
  if (!next_line(&line) || line != "ply") throw InputError(path, "not a PLY file (no 'ply' magic)");
  for (;;) {
    if (!next_line(&line)) throw InputError(path, "PLY header has no end_header line");
    if (!printable(line)) throw fail("binary data inside the header");
    const std::vector<std::string_view> w = split_words(line);
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (w.size() < 2) throw fail("format line without a format");
      if (w[1] == "ascii")
        h.format = PlyFormat::kAscii;
      else if (w[1] == "binary_little_endian")
        h.format = PlyFormat::kBinaryLittleEndian;
      else if (w[1] == "binary_big_endian")
        h.format = PlyFormat::kBinaryBigEndian;
      else
        throw fail("unknown format '" + std::string(w[1]) + "'");
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) throw fail("expected 'element NAME COUNT'");
      PlyElement e;
      e.name = std::string(w[1]);
      const std::string_view c = w[2];
      const auto r = std::from_chars(c.data(), c.data() + c.size(), e.count);
      if (r.ec != std::errc() || r.ptr != c.data() + c.size())
        throw fail("element '" + e.name + "' has an invalid count '" + std::string(c) + "'");
      h.elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (h.elements.empty()) throw fail("property before any element");
      PlyProperty p;
      if (w.size() >= 2 && w[1] == "list") {
        if (w.size() != 5) throw fail("expected 'property list COUNT_TYPE ITEM_TYPE NAME'");
        if (!parse_type(w[2], &p.count_type))
          throw fail("unknown property type '" + std::string(w[2]) + "'");
        if (!parse_type(w[3], &p.type))
          throw fail("unknown property type '" + std::string(w[3]) + "'");
        if (!ply_type_is_integer(p.count_type))
          throw fail("list count type must be an integer type");
        p.is_list = true;
        p.name = std::string(w[4]);
      } else {
        if (w.size() != 3) throw fail("expected 'property TYPE NAME'");
        if (!parse_type(w[1], &p.type))
          throw fail("unknown property type '" + std::string(w[1]) + "'");
        p.name = std::string(w[2]);
      }
      h.elements.back().properties.push_back(std::move(p));
    }
    // Any other keyword is ignored like a comment (see the header file).
  }
  if (!have_format) throw InputError(path, "PLY header has no format line");
  h.data_offset = pos;
  return h;
}

}  // namespace hprt
