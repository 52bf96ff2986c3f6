#include "bench/trace_suite.h"

#include <filesystem>
#include <utility>

#include "meshgen/mesh_generators.h"

#ifndef HPRT_SOURCE_DATA_DIR
#define HPRT_SOURCE_DATA_DIR "data"
#endif

namespace hprt::bench {
namespace {

constexpr const char* kRealMeshes[] = {"dragon.ply.gz", "happy_buddha.obj", "lucy.obj",
                                       "armadillo.obj", "sponza.obj.gz"};

BenchInput generated(TriangleMesh mesh, const char* kind, size_t tris) {
  mesh.name = std::string(kind) + "-" + std::to_string(mesh.triangles.size());
  return framed_input(std::move(mesh), "generated: hprt generate " + std::string(kind) +
                                           " --tris " + std::to_string(tris) + " --seed 1");
}

}  // namespace

std::vector<std::string> default_suite_meshes() {
  namespace fs = std::filesystem;
  const fs::path dirs[] = {"../shared/data/meshes", fs::path(HPRT_SOURCE_DATA_DIR) / ".." / ".." /
                                                        "shared" / "data" / "meshes"};
  fs::path dir = dirs[0];
  for (const fs::path& d : dirs)
    if (fs::is_directory(d)) {
      dir = d;
      break;
    }
  std::vector<std::string> out;
  for (const char* name : kRealMeshes) out.push_back((dir / name).lexically_normal().string());
  return out;
}

Suite load_suite(size_t tris, const std::vector<std::string>& meshes, bool with_default_meshes) {
  Suite suite;
  suite.inputs.push_back(generated(generate_bumpy_sphere(tris, 1), "bumpy", tris));
  suite.inputs.push_back(generated(generate_soup(tris, 1), "soup", tris));
  suite.inputs.push_back(generated(generate_sliver_sheet(tris, 1), "sheet", tris));
  if (!meshes.empty()) {
    for (const std::string& path : meshes) suite.inputs.push_back(file_input(path));
  } else if (with_default_meshes) {
    for (const std::string& path : default_suite_meshes()) {
      if (std::filesystem::exists(path))
        suite.inputs.push_back(file_input(path));
      else
        suite.skipped.push_back(path);
    }
  }
  return suite;
}

}  // namespace hprt::bench
