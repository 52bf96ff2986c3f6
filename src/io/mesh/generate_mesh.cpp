// Dispatch from a GenerateSpec to the generator of its kind, with the option
// checks shared by the CLI and the scene reader.
#include "io/mesh/generate_mesh.h"

#include "core/error.h"
#include "io/mesh/mesh_reader.h"

namespace hprt {

const std::vector<std::string>& generator_kinds() {
  static const std::vector<std::string> kinds{"sphere", "bumpy",   "torus", "soup",     "slivers",
                                              "sheet",  "terrain", "plane", "subdivide"};
  return kinds;
}

TriangleMesh generate_mesh(const GenerateSpec& spec) {
  if (spec.tris == 0) throw OptionError("tris", "need at least 1 triangle, got 0");
  if (spec.tris > kMaxGenerateTriangles)
    throw OptionError("tris", "too many triangles: " + std::to_string(spec.tris) + " (at most " +
                                  std::to_string(kMaxGenerateTriangles) + ")");
  if (spec.kind != "subdivide" && !spec.from.empty())
    throw OptionError("from", "only used by 'subdivide', not '" + spec.kind + "'");
  if (spec.kind == "sphere") return generate_sphere(spec.tris);
  if (spec.kind == "bumpy") return generate_bumpy_sphere(spec.tris, spec.seed);
  if (spec.kind == "torus") return generate_torus(spec.tris);
  if (spec.kind == "soup") return generate_soup(spec.tris, spec.seed);
  if (spec.kind == "slivers") return generate_slivers(spec.tris, spec.seed);
  if (spec.kind == "sheet") return generate_sliver_sheet(spec.tris, spec.seed);
  if (spec.kind == "terrain") return generate_terrain(spec.tris, spec.seed);
  if (spec.kind == "plane") return generate_plane(spec.tris);
  if (spec.kind == "subdivide") {
    if (spec.from.empty()) throw OptionError("from", "'subdivide' needs an input mesh");
    TriangleMesh mesh = subdivide_mesh(load_mesh(spec.from), spec.tris);
    mesh.normals.clear();
    return mesh;
  }
  std::string known;
  for (const std::string& k : generator_kinds()) known += (known.empty() ? "" : ", ") + k;
  throw InputError("generate", "unknown kind '" + spec.kind + "' (known: " + known + ")");
}

}  // namespace hprt
