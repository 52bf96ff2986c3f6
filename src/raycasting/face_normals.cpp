#include "raycasting/face_normals.h"

namespace hprt::raycasting {

FaceNormals::FaceNormals(const api::Scene& scene) {
  for (uint32_t g = 0; g < scene.mesh_count(); ++g) {
    first_.push_back(triangles_);
    triangles_ += scene.indices(g).size() / 3;
  }
  normals_ = std::make_unique_for_overwrite<float[]>(3 * triangles_);
  for (uint32_t g = 0; g < scene.mesh_count(); ++g)
    scene.normals(g, {normals_.get() + 3 * first_[g], 3 * (scene.indices(g).size() / 3)});
}

}  // namespace hprt::raycasting
