// The binned builders' working array: one 32-byte reference per primitive,
// its box as two SSE vectors with the PrimInfo index in lo's w lane (as
// Embree's PrimRef), so binning and partition stream one array and never
// gather through an index. Lane 3 of any box math on refs is garbage and is
// never read back.
#pragma once

#include <immintrin.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>

#include "bvh/input/prim_info.h"
#include "core/aabb.h"

namespace hprt {

struct alignas(32) BoxRef {
  __m128 lo;  // min.xyz, w: PrimInfo index (bits)
  __m128 hi;  // max.xyz, w: 0

  uint32_t index() const {
    return static_cast<uint32_t>(
        _mm_cvtsi128_si32(_mm_shuffle_epi32(_mm_castps_si128(lo), _MM_SHUFFLE(3, 3, 3, 3))));
  }
  // The box centre, bit for bit AABB::center() in lanes 0-2, and 0 in lane 3
  // (index bits are denormals as floats: arithmetic on them is slow). The asm
  // keeps the compiler from fusing the * 0.5 into a later subtraction.
  __m128 center() const {
    const __m128 xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    __m128 c = _mm_mul_ps(_mm_add_ps(_mm_and_ps(lo, xyz), hi), _mm_set1_ps(0.5f));
    asm("" : "+x"(c));
    return c;
  }
};
static_assert(sizeof(BoxRef) == 32);

inline BoxRef make_box_ref(const AABB& b, uint32_t index) {
  float idx;
  static_assert(sizeof idx == sizeof index);
  __builtin_memcpy(&idx, &index, sizeof idx);
  return {_mm_setr_ps(b.min.x, b.min.y, b.min.z, idx), _mm_setr_ps(b.max.x, b.max.y, b.max.z, 0)};
}

// refs[i] for i in [begin, end): box i of prims, index i.
inline void fill_box_refs(const PrimInfo& prims, BoxRef* refs, size_t begin, size_t end) {
  const AABB* b = prims.bounds.data();
  for (size_t i = begin; i < end; ++i) refs[i] = make_box_ref(b[i], static_cast<uint32_t>(i));
}

inline AABB vec_to_aabb(__m128 lo, __m128 hi) {
  alignas(16) float l[4], h[4];
  _mm_store_ps(l, lo);
  _mm_store_ps(h, hi);
  return AABB({l[0], l[1], l[2]}, {h[0], h[1], h[2]});
}

// AABB::half_area() of a non-empty box (lo, hi), (xy + yz) + zx of the
// diagonal; the asm keeps the products from being fused into the sums, so
// every call gives the same bits.
inline float vec_half_area(__m128 lo, __m128 hi) {
  const __m128 d = _mm_sub_ps(hi, lo);
  __m128 p = _mm_mul_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 0, 2, 1)));  // xy, yz, zx
  asm("" : "+x"(p));
  const __m128 s = _mm_add_ss(p, _mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 1, 1, 1)));
  return _mm_cvtss_f32(_mm_add_ss(s, _mm_movehl_ps(p, p)));
}

// A box as lo/hi vectors (lanes 0-2), empty at first.
struct VecBox {
  __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
  __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());

  void extend(__m128 p) {
    lo = _mm_min_ps(lo, p);
    hi = _mm_max_ps(hi, p);
  }
  void extend(__m128 l, __m128 h) {
    lo = _mm_min_ps(lo, l);
    hi = _mm_max_ps(hi, h);
  }
  AABB aabb() const { return vec_to_aabb(lo, hi); }
};

// Union of boxes and of centres of refs[0, n).
inline std::pair<AABB, AABB> ref_bounds(const BoxRef* refs, size_t n) {
  VecBox b, c;
  for (size_t i = 0; i < n; ++i) {
    b.extend(refs[i].lo, refs[i].hi);
    c.extend(refs[i].center());
  }
  return {b.aabb(), c.aabb()};
}

}  // namespace hprt
