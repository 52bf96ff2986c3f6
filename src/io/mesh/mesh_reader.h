// Mesh loading by extension: .obj (tinyobjloader), .ply (our reader), either
// optionally .gz (zlib). Throws InputError "path: problem".
#pragma once

#include <string>

#include "core/triangle_mesh.h"

namespace hprt {

TriangleMesh load_mesh(const std::string& path);

}  // namespace hprt
