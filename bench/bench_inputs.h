// Inputs of the benchmarks: meshes generated at an exact triangle count (a
// closed torus, cut to the count), mesh and scene files, and the report's
// Table 1 sizes with the real meshes that stand for its models.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/scene.h"

namespace hprt::bench {

struct BenchInput {
  std::string label;         // short name in tables: "torus-132267" or the file name
  std::string source;        // how it was made or where it was read from
  std::string report_model;  // the report's model this stands for, or ""
  Scene scene;
};

// The triangle counts of the report's Table 1 models.
struct ReportModel {
  size_t triangles;
  const char* name;        // the report's model
  const char* real_mesh;   // our real stand-in under ../shared/data/meshes
  const char* real_notes;  // how it relates
};
const std::vector<ReportModel>& report_models();

// `mesh` alone, labelled by its name, framed by the default camera and head
// light of a bare mesh file.
BenchInput framed_input(TriangleMesh mesh, std::string source);

// A torus (hprt generate torus) with the smallest grid of at least `tris`
// triangles, its last triangles dropped so it has exactly `tris` (a sliver of
// an open seam; harmless for build and trace timing). Framed by the default
// camera and head light of a bare mesh.
BenchInput generated_input(size_t tris);

// A mesh file (OBJ/PLY, .gz) or scene JSON through load_scene (InputError
// naming the path when missing or malformed). `report_model` is filled when
// the file is one of the real stand-ins.
BenchInput file_input(const std::string& path);

// "1,087,474"
std::string with_commas(size_t n);

}  // namespace hprt::bench
