// Line-by-line syntax check of Wavefront OBJ text, run before tinyobjloader
// (which skips unknown lines and reads unparsable numbers as 0 silently), so
// that every malformed line is an InputError naming the file and line.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/vec.h"

namespace hprt {

struct ObjTextSummary {
  size_t vertices = 0;   // `v` lines
  size_t normals = 0;    // `vn` lines
  size_t faces = 0;      // `f` lines
  size_t triangles = 0;  // after fan triangulation
  // `v` lines holding nan/inf or out-of-float-range values, which
  // tinyobjloader does not read faithfully: (vertex index, exact value).
  std::vector<std::pair<size_t, Vec3f>> non_finite_vertices;
};

// Checks every line: known statement keyword, numbers that parse (v: 3-7,
// vn: 3, vt/vp: 1-3), faces of at least 3 references `v`, `v/t`, `v//n` or
// `v/t/n` with nonzero indices that resolve inside the v/vt/vn lists (relative
// negative indices against the lines so far), no control bytes (binary data).
// Throws InputError(path, "line N: problem").
ObjTextSummary validate_obj_text(const std::string& path, std::string_view text);

}  // namespace hprt
