// Self-intersection-free origins for secondary rays: Wächter & Binder, "A Fast
// and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems (2019),
// ch. 6. The point moves along the normal by a few ulps (integer arithmetic on
// the float bits), so the offset scales with |p|; near the origin, where ulps
// are tiny, a fixed float offset is used instead.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include "core/vec.h"

namespace hprt {

// The constants of the chapter's Listing 6-1.
constexpr float offset_origin() { return 1.0f / 32.0f; }          // below: fixed offset
constexpr float offset_float_scale() { return 1.0f / 65536.0f; }  // fixed offset per unit n
constexpr float offset_int_scale() { return 256.0f; }             // ulps per unit n

// The chapter's 256 ulps cover hit points computed as org + t dir by GPU
// hardware. hprt reconstructs hit points from the vertices and barycentrics
// (p = w a + u b + v c), within a few ulps of max|coordinate|, so the
// renderer offsets by 16 ulps: 256 ulps is 16 units at 1e6 (ulp 0.0625),
// which lifts shadow rays over whole objects and loses contact shadows there
// (tests/render/test_whitted.cpp NoAcneFarFromOrigin). At the origin both give the
// same images; 4 ulps starts to show acne.
constexpr float kBarycentricHitIntScale = 16.0f;

namespace detail {
inline float offset_component(float p, float n, float int_scale) {
  if (std::fabs(p) < offset_origin()) return p + offset_float_scale() * n;
  const int32_t of_i = int32_t(int_scale * n);
  // Moving the bit pattern up increases |p|: add for p >= 0, subtract for p < 0.
  return std::bit_cast<float>(std::bit_cast<int32_t>(p) + (p < 0.0f ? -of_i : of_i));
}
}  // namespace detail

// p: a point on the surface (best reconstructed from barycentrics); n: the
// unit geometric normal on the side the new ray leaves from; int_scale: ulps
// moved per unit of normal (see above).
inline Vec3f offset_ray(const Vec3f& p, const Vec3f& n, float int_scale = offset_int_scale()) {
  return {detail::offset_component(p.x, n.x, int_scale),
          detail::offset_component(p.y, n.y, int_scale),
          detail::offset_component(p.z, n.z, int_scale)};
}

}  // namespace hprt
