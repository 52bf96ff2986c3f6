// What an answer must be to be trusted, whichever backend gave it: a hit
// on a valid ray (core/ray.h) with t finite and in the ray's (tnear, tfar]
// (Embree's interval), ids naming a triangle of
// the scene and barycentrics inside that triangle (to float rounding); a
// miss with both ids invalid. The plugin backend checks every answer with
// it and the ray diff counts a failure as a wrong answer.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "core/hit.h"
#include "core/ray.h"
#include "core/scene.h"

namespace hprt {

// Rounding of u = U/det, v = W/det to float can leave them a few ulps
// outside [0, 1]; anything farther is not rounding.
inline constexpr float kBarycentricSlack = 1e-5f;

inline bool hit_well_formed(const Scene& scene, const Ray& ray, const Hit& h) {
  if (!h.hit()) return h.geom_id == kInvalidId && !std::isnan(h.t);
  if (!ray_valid(ray)) return false;  // such rays miss on every backend
  if (h.geom_id >= scene.meshes.size()) return false;
  if (h.prim_id >= scene.meshes[h.geom_id].triangle_count()) return false;
  if (!(std::isfinite(h.t) && h.t > ray.tnear && h.t <= ray.tfar)) return false;
  return h.u >= -kBarycentricSlack && h.v >= -kBarycentricSlack &&
         h.u + h.v <= 1.0f + kBarycentricSlack;  // false for NaN too
}

// An occlusion answer is one byte, 0 or 1.
inline bool occlusion_well_formed(uint8_t occluded) { return occluded <= 1; }

// The warning every command that traces through a backend prints after
// "<command>: warning: " when answers failed these checks (empty when none
// did), so a broken plugin is never timed or rendered as if it were right.
inline std::string malformed_warning(const std::string& backend_name, uint64_t malformed) {
  if (malformed == 0) return {};
  return backend_name + " gave " + std::to_string(malformed) +
         " malformed answers (t outside [tnear, tfar], ids out of range, u/v outside the "
         "triangle, a record left unwritten, or a byte not 0/1); hits taken as misses with "
         "t = NaN, such bytes as occluded";
}

}  // namespace hprt
