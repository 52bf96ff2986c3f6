// Everything a render or a ray query needs: meshes (geomID = index here),
// camera, lights and global shading settings.
#pragma once

#include <cstddef>
#include <vector>

#include "core/aabb.h"
#include "core/animation.h"
#include "core/camera.h"
#include "core/light.h"
#include "core/triangle_mesh.h"

namespace hprt {

struct Scene {
  std::vector<TriangleMesh> meshes;
  Camera camera;
  std::vector<Light> lights;
  Vec3f background{0.05f, 0.05f, 0.08f};
  Vec3f ambient{0.1f, 0.1f, 0.1f};
  int max_depth = 5;
  Animation animation;

  void add_mesh(TriangleMesh mesh) {
    mesh.pad_for_embree();
    meshes.push_back(std::move(mesh));
  }
  size_t triangle_count() const {
    size_t n = 0;
    for (const auto& m : meshes) n += m.triangle_count();
    return n;
  }
  AABB bounds() const {
    AABB b;
    for (const auto& m : meshes) b.extend(m.bounds());
    return b;
  }
};

}  // namespace hprt
