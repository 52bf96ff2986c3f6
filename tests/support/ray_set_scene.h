// The scene the ray-set tests share: one mesh around the origin, seen from
// (0, 0, 4) at 64x48 and lit by a point light at (3, 4, 5).
#pragma once

#include <utility>

#include "core/scene.h"

namespace hprt::test {

inline Scene ray_set_scene(TriangleMesh mesh) {
  Scene s;
  s.add_mesh(std::move(mesh));
  s.camera.position = {0.0f, 0.0f, 4.0f};
  s.camera.width = 64;
  s.camera.height = 48;
  Light light;
  light.position = {3.0f, 4.0f, 5.0f};
  s.lights.push_back(light);
  return s;
}

}  // namespace hprt::test
