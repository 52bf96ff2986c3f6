// load_mesh: reads the file (gunzipping .gz), dispatches on the extension
// (case-insensitive) to the OBJ or PLY reader, and rejects meshes without
// triangles (point clouds, empty files) since nothing could be traced.
#include "io/mesh/mesh_reader.h"

#include "core/error.h"
#include "io/files/file_bytes.h"
#include "io/mesh/obj_reader.h"
#include "io/mesh/ply_reader.h"

namespace hprt {

TriangleMesh load_mesh(const std::string& path) {
  const std::string ext = mesh_extension(path);
  if (ext != ".obj" && ext != ".ply")
    throw InputError(path, "unknown mesh format (expected .obj or .ply, optionally .gz)");
  const std::string bytes = read_file_bytes(path);
  if (bytes.empty()) throw InputError(path, "empty file");
  TriangleMesh mesh = ext == ".obj" ? read_obj(path, bytes) : read_ply(path, bytes);
  if (mesh.triangles.empty()) throw InputError(path, "mesh has no triangles");
  mesh.name = path;
  return mesh;
}

}  // namespace hprt
