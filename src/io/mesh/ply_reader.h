// PLY reader: ASCII, binary little and big endian; vertex x/y/z (+nx/ny/nz) of
// any scalar type; `face` lists fan-triangulated; `tristrips` lists unrolled.
// Every other element and property is skipped.
#pragma once

#include <string>
#include <string_view>

#include "core/triangle_mesh.h"

namespace hprt {

// Parses a whole PLY file held in memory. `path` names it in errors and
// becomes mesh.name. Triangle order (the primID) is file order: face k with n
// indices gives the n-2 triangles (v0, vi, vi+1); a face with fewer than 3
// indices gives none. A tristrip run s0 s1 s2 ... (-1 restarts a run) gives
// (s_j, s_j+1, s_j+2) for every j, with the first two swapped on odd j so all
// share one winding; triangles with a repeated index (the joints strips use to
// turn) are not emitted. Throws InputError(path, ...) on any malformed,
// truncated or inconsistent input, before allocating what a header claims
// when the file is too small to hold it.
TriangleMesh read_ply(const std::string& path, std::string_view bytes);

}  // namespace hprt
