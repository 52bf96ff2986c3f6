// Closest hits as separate arrays instead of Hit records
// (Intersector::intersect_columns), as numpy and Open3D users hold them.
// Each pointer is null (not wanted) or holds one entry per ray of the batch
// (uv 2, normal 3). A miss: t = +inf, both ids kInvalidId, uv and normal 0;
// a plugin's malformed answer (core/hit_check.h) the same with t = NaN.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "core/hit.h"

namespace hprt {

struct HitColumns {
  float* t = nullptr;
  uint32_t* geom_id = nullptr;
  uint32_t* prim_id = nullptr;
  float* uv = nullptr;
  float* normal = nullptr;

  // The same columns from ray `first` on.
  HitColumns from(size_t first) const {
    return {t ? t + first : nullptr, geom_id ? geom_id + first : nullptr,
            prim_id ? prim_id + first : nullptr, uv ? uv + 2 * first : nullptr,
            normal ? normal + 3 * first : nullptr};
  }

  // Ray i's answer: the record `h` (a plugin's malformed hit, t = NaN, is a
  // miss here too, keeping its NaN) and, for a hit, its unit normal n (3 floats).
  void write(size_t i, const Hit& h, const float* n) const {
    const bool hit = h.hit();
    if (t) t[i] = hit || h.t != h.t ? h.t : std::numeric_limits<float>::infinity();
    if (geom_id) geom_id[i] = hit ? h.geom_id : kInvalidId;
    if (prim_id) prim_id[i] = hit ? h.prim_id : kInvalidId;
    if (uv) uv[2 * i] = hit ? h.u : 0.0f, uv[2 * i + 1] = hit ? h.v : 0.0f;
    if (normal) {
      float* o = normal + 3 * i;
      o[0] = hit ? n[0] : 0.0f, o[1] = hit ? n[1] : 0.0f, o[2] = hit ? n[2] : 0.0f;
    }
  }
  void write_miss(size_t i) const { write(i, Hit{}, nullptr); }
};

}  // namespace hprt
