// Whether a group of rays is worth tracing as one packet: all valid, origins
// within `max_origin_offset` of the first one's (per component), directions
// within ~25 degrees (cos >= 0.9) of the first one's: camera rays, and the
// shadow and mirror rays of neighbouring pixels, not random or scattered
// ones. Both backends use it, so they pick the same groups.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/ray.h"

namespace hprt {

// max_origin_offset as a fraction of the scene's largest extent: wide enough
// that the shadow and reflection rays of neighbouring pixels qualify (with
// 1/1000 almost none would), and packets of them still trace faster than
// single rays in both backends.
inline constexpr float kCoherentOriginFraction = 0.05f;

inline bool rays_coherent(const Ray* r, size_t n, float max_origin_offset) {
  if (n == 0 || !ray_valid(r[0])) return false;
  const Vec3f d0 = normalize(r[0].dir);  // tiny or huge dirs give NaN below
  for (size_t i = 1; i < n; ++i) {
    if (!ray_valid(r[i])) return false;
    const Vec3f o = r[i].org - r[0].org;
    if (std::max({std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)}) > max_origin_offset)
      return false;
    if (!(dot(normalize(r[i].dir), d0) >= 0.9f)) return false;  // NaN: not coherent
  }
  return true;
}

}  // namespace hprt
