// One entry point for every procedural mesh (meshgen/mesh_generators.h), shared
// by `hprt generate` and the scene reader's "generate" blocks; `subdivide`
// loads its input with load_mesh, which is why this lives in io.
#pragma once

#include <string>
#include <vector>

#include "meshgen/mesh_generators.h"

namespace hprt {

// The kinds generate_mesh accepts, in the order `hprt generate --help` lists them.
const std::vector<std::string>& generator_kinds();

// Builds the mesh `spec` describes. Throws InputError naming the option:
// "--tris" (0 or above kMaxGenerateTriangles: "too many triangles"), "--from"
// (missing for subdivide, or the input mesh's own errors), or the kind.
TriangleMesh generate_mesh(const GenerateSpec& spec);

}  // namespace hprt
