#include "backends/mesh_record.h"

#include <cstdint>

namespace hprt {

void MeshRecord::record(const Scene& scene, const PrimInfo& prims) {
  meshes_.resize(scene.meshes.size());
  for (size_t g = 0; g < scene.meshes.size(); ++g)
    meshes_[g] = {scene.meshes[g].vertex_count(), scene.meshes[g].triangle_count()};
  invalid_.clear();
  if (prims.invalid == 0) return;
  invalid_.reserve(prims.invalid);
  for (size_t g = 0; g < scene.meshes.size(); ++g)
    for (size_t i = 0; i < scene.meshes[g].triangle_count(); ++i)
      if (!scene.meshes[g].triangle_valid(i))
        invalid_.push_back({static_cast<uint32_t>(g), static_cast<uint32_t>(i)});
}

bool MeshRecord::same_meshes(const Scene& scene) const {
  if (scene.meshes.size() != meshes_.size()) return false;
  for (size_t g = 0; g < meshes_.size(); ++g)
    if (meshes_[g].vertices != scene.meshes[g].vertex_count() ||
        meshes_[g].triangles != scene.meshes[g].triangle_count())
      return false;
  return true;
}

bool MeshRecord::invalid_became_valid(const Scene& scene) const {
  for (const PrimRef& r : invalid_)
    if (scene.meshes[r.geom_id].triangle_valid(r.prim_id)) return true;
  return false;
}

}  // namespace hprt
