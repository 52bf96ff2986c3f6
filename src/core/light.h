// Point and directional lights, as in the scene schema.
#pragma once

#include "core/vec.h"

namespace hprt {

enum class LightType { kPoint, kDirectional };

struct Light {
  LightType type = LightType::kPoint;
  Vec3f position{0.0f, 0.0f, 0.0f};    // point lights
  Vec3f direction{0.0f, -1.0f, 0.0f};  // directional lights: direction light travels
  Vec3f intensity{1.0f, 1.0f, 1.0f};
};

}  // namespace hprt
