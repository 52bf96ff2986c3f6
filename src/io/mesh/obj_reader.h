// Wavefront OBJ reader on top of tinyobjloader's callback API, after a strict
// syntax check (obj_validate.h).
#pragma once

#include <string>
#include <string_view>

#include "core/triangle_mesh.h"

namespace hprt {

// Parses OBJ text held in memory; `path` names it in errors, becomes
// mesh.name, and locates `mtllib` files (relative to its directory).
// - All objects and groups become one mesh; primID is file order after fan
//   triangulation: face k with n vertices gives (v0, vi, vi+1), i = 1..n-2.
// - Material: the .mtl material used by the most triangles (ties: the one
//   used first) gives diffuse = Kd, specular = Ks, shininess = Ns; faces with
//   no or an unknown material do not vote; with none, Material{}. A missing
//   .mtl file or material name is not an error (many exporters leave them).
// - Normals (vn) are kept when every face vertex has one: a position whose
//   face vertices all use the same vn gets it as is; one referenced with
//   different vn gets the normalised sum of the unit normals referenced
//   (smooth shading); positions no face uses get (0,0,0).
// - nan/inf coordinates are kept (such triangles are invalid, not errors).
TriangleMesh read_obj(const std::string& path, std::string_view text);

}  // namespace hprt
