// Surface description used by the Whitted shader: Lambert diffuse, Blinn-Phong
// specular, mirror reflectivity. Nothing else is modelled.
#pragma once

#include "core/vec.h"

namespace hprt {

struct Material {
  Vec3f diffuse{0.8f, 0.8f, 0.8f};
  Vec3f specular{0.0f, 0.0f, 0.0f};
  float shininess = 32.0f;
  float reflectivity = 0.0f;
  bool operator==(const Material&) const = default;
};

}  // namespace hprt
