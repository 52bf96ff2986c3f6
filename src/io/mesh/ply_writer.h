// Writes a TriangleMesh as PLY (binary little endian by default), atomically.
#pragma once

#include <string>

#include "core/triangle_mesh.h"

namespace hprt {

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

void write_ply(const TriangleMesh& mesh, const std::string& path,
               PlyFormat format = PlyFormat::kBinaryLittleEndian);

}  // namespace hprt
