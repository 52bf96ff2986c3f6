// A ray as Embree 3 sees it: origin, direction (not necessarily unit length)
// and the parametric interval [tnear, tfar]. The layout is one 32-byte record
// of the .rays file format.
#pragma once

#include <cmath>
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

// Embree's FLT_LARGE: RayK::valid() in Embree 3's kernels/common/ray.h.
inline constexpr float kRayComponentLimit = 1.844e18f;

// The one definition of a valid ray, shared by every backend and the arbiter:
// origin and direction components finite and within Embree's FLT_LARGE, a
// non-zero direction, and 0 <= tnear <= tfar. Embree leaves anything else
// undefined (Debian's build even asserts on tnear < 0), so hprt defines all
// such rays as misses.
inline bool ray_valid(const Ray& r) {
  for (int k = 0; k < 3; ++k)  // written so that NaN fails too
    if (!(std::fabs(r.org[k]) <= kRayComponentLimit) ||
        !(std::fabs(r.dir[k]) <= kRayComponentLimit))
      return false;
  if (r.dir.x == 0.0f && r.dir.y == 0.0f && r.dir.z == 0.0f) return false;
  return r.tnear >= 0.0f && r.tnear <= r.tfar;  // false when either is NaN
}

}  // namespace hprt
