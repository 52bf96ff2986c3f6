// The large-mesh suite of `hprt bench trace`: meshes the bench's own scenes
// do not cover, where traversal is memory-bound. Generated meshes of three
// characters (a closed scan-like bumpy sphere, a soup of small random
// triangles, a terrain sheet of 100:1 slivers) and real scanned or modelled
// meshes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "bench/bench_inputs.h"

namespace hprt::bench {

// The real meshes of ../shared/data/meshes at full size: dragon.ply.gz,
// happy_buddha.obj, lucy.obj, armadillo.obj, sponza.obj.gz, looked up under
// ./../shared/data/meshes and beside the source tree.
std::vector<std::string> default_suite_meshes();

struct Suite {
  std::vector<BenchInput> inputs;
  std::vector<std::string> skipped;  // default meshes that are absent
};

// Generated meshes of `tris` triangles (hprt generate bumpy|soup|sheet,
// seed 1) and the mesh files: `meshes`, each required (InputError when
// missing), or, when `meshes` is empty and `with_default_meshes`, those of
// default_suite_meshes() that exist.
Suite load_suite(size_t tris, const std::vector<std::string>& meshes, bool with_default_meshes);

}  // namespace hprt::bench
