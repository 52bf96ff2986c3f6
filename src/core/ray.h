// A ray as Embree 3 sees it: origin, direction (not necessarily unit length)
// and the parametric interval [tnear, tfar]. The layout is one 32-byte record
// of the .rays file format.
#pragma once

#include <limits>

#include "core/vec.h"

namespace hprt {

struct Ray {
  Vec3f org;
  float tnear = 0.0f;
  Vec3f dir;
  float tfar = std::numeric_limits<float>::infinity();
};
static_assert(sizeof(Ray) == 32, "Ray must match the 32-byte .rays record");

}  // namespace hprt
