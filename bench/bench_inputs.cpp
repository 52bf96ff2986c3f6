// Benchmark inputs: exact-count generated meshes and files.
#include "bench/bench_inputs.h"

#include <filesystem>
#include <utility>

#include "io/scene/scene_reader.h"
#include "meshgen/mesh_generators.h"

namespace hprt::bench {

const std::vector<ReportModel>& report_models() {
  static const std::vector<ReportModel> models = {
      {132267, "Sponza", "sponza.obj.gz",
       "66,454 tris: the Dabrovic Sponza, a smaller version of the report's Sponza"},
      {871306, "Stanford dragon", "dragon.ply.gz",
       "871,414 tris: the very Stanford dragon of the report (108 more in this file)"},
      {1087474, "Happy Buddha", "happy_buddha.obj",
       "112,876 tris: a decimated Happy Buddha, about a tenth of the report's"},
  };
  return models;
}

std::string with_commas(size_t n) {
  const std::string digits = std::to_string(n);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out.push_back(',');
    out.push_back(digits[i]);
  }
  return out;
}

BenchInput framed_input(TriangleMesh mesh, std::string source) {
  BenchInput in;
  in.label = mesh.name;
  in.source = std::move(source);
  in.scene.add_mesh(std::move(mesh));
  Camera lens;  // default lens, framed on the mesh like a bare mesh file
  in.scene.camera = framing_camera(in.scene.bounds(), lens);
  in.scene.lights.push_back(head_light(in.scene.camera));
  return in;
}

BenchInput generated_input(size_t tris) {
  TriangleMesh mesh = generate_torus(tris);
  const size_t full = mesh.triangles.size();
  mesh.triangles.resize(tris);
  mesh.name = "torus-" + std::to_string(tris);
  BenchInput in = framed_input(std::move(mesh), "generated torus of " + with_commas(full) +
                                                    " triangles cut to " + with_commas(tris));
  for (const auto& m : report_models())
    if (m.triangles == tris) in.report_model = std::string(m.name) + " (size)";
  return in;
}

BenchInput file_input(const std::string& path) {
  BenchInput in;
  in.scene = load_scene(path);
  in.label = std::filesystem::path(path).filename().string();
  in.source = path;
  for (const auto& m : report_models())
    if (in.label == m.real_mesh) in.report_model = m.name;
  return in;
}

}  // namespace hprt::bench
