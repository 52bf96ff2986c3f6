// Closest-hit answer, one 20-byte record of the .hits file format. u, v are
// the barycentrics of vertices 1 and 2 (Embree's convention).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace hprt {

inline constexpr uint32_t kInvalidId = 0xFFFFFFFFu;

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f;
  float v = 0.0f;
  uint32_t geom_id = kInvalidId;
  uint32_t prim_id = kInvalidId;

  constexpr bool hit() const { return prim_id != kInvalidId; }
  // A plugin's answer that failed hit_well_formed() (core/hit_check.h), kept
  // as a miss (so nothing indexes with its ids) that validators still count
  // as wrong: no backend reports a NaN t on a real miss.
  bool malformed() const { return prim_id == kInvalidId && std::isnan(t); }
};

inline Hit malformed_hit() {
  Hit h;
  h.t = std::numeric_limits<float>::quiet_NaN();
  return h;
}
static_assert(sizeof(Hit) == 20, "Hit must match the 20-byte .hits record");

}  // namespace hprt
