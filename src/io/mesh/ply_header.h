// PLY header model and parser: format line, elements with scalar and list
// properties (Greg Turk's PLY spec, with the int8..float64 type aliases).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh/ply_writer.h"

namespace hprt {

enum class PlyType : uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

size_t ply_type_size(PlyType t);
bool ply_type_is_integer(PlyType t);

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;  // lists only
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;

  bool has_list() const;
  // Smallest number of bytes one binary record can take (lists empty).
  size_t min_binary_record_bytes() const;
  // Index of the property called `name`, or -1.
  int find(std::string_view name) const;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  size_t data_offset = 0;  // first byte after the end_header line
};

// Parses the header at the start of `bytes`. Accepts LF and CRLF line ends.
// Lines with an unknown keyword are ignored like comments (Blender 2.4x
// exports write a bare "Created by ..." line, see assimp's Wuson.ply).
// Throws InputError(path, ...) for a file that is not PLY, an unknown format
// or property type, a property outside an element, or a missing end_header.
PlyHeader parse_ply_header(const std::string& path, std::string_view bytes);

}  // namespace hprt
