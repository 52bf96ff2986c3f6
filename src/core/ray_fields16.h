// Sixteen Ray records as eight AVX-512 vectors, one per field (org x, y, z,
// tnear, dir x, y, z, tfar), ray l in lane l: the layout a packet's lanes and
// the 16-lane coherence test read. Eight plain loads and a transpose
// (core/transpose16x8.h), not eight gathers: a gather of records not yet in
// the caches stalls until all its 16 loads are back, where plain loads of
// the same lines overlap with the work around them.
#pragma once

#if defined(__AVX512F__)

#include <immintrin.h>

#include <cstddef>

#include "core/force_inline.h"
#include "core/ray.h"
#include "core/transpose16x8.h"

namespace hprt {

// out[k] = field k of r[0..16), ray l in lane l.
HPRT_FORCE_INLINE void load_ray_fields16(const Ray* r, __m512 out[8]) {
  static_assert(sizeof(Ray) == 8 * sizeof(float) && offsetof(Ray, tnear) == 3 * sizeof(float) &&
                offsetof(Ray, dir) == 4 * sizeof(float) &&
                offsetof(Ray, tfar) == 7 * sizeof(float));
  const float* f = &r[0].org.x;
  __m512 a[8];
  for (int j = 0; j < 8; ++j) a[j] = _mm512_loadu_ps(f + 16 * j);  // rays 2j, 2j + 1
  transpose_records16(a, out);
}

}  // namespace hprt

#endif  // __AVX512F__
