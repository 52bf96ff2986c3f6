// What a tree was built over, so that update() can tell whether a refit can
// stand: per mesh its vertex and triangle counts, and the triangles left out
// as invalid (degenerate or non-finite; usually none). The tree only holds
// the triangles that were valid at its build.
#pragma once

#include <cstddef>
#include <vector>

#include "bvh/input/prim_info.h"
#include "core/scene.h"

namespace hprt {

class MeshRecord {
 public:
  // Records `scene` as built (prims: its prim info, for the invalid count).
  void record(const Scene& scene, const PrimInfo& prims);
  // Forgets the record: the next update() finds the meshes changed.
  void clear() { meshes_.clear(); }
  // Whether the recorded tree still fits `scene`: the same number of meshes
  // with the same vertex and triangle counts, and no triangle left out at
  // the build valid now.
  bool fits(const Scene& scene) const { return same_meshes(scene) && !invalid_became_valid(scene); }

 private:
  bool same_meshes(const Scene& scene) const;
  bool invalid_became_valid(const Scene& scene) const;  // only after same_meshes

  struct Counts {
    size_t vertices = 0;
    size_t triangles = 0;
  };
  std::vector<Counts> meshes_;
  std::vector<PrimRef> invalid_;
};

}  // namespace hprt
