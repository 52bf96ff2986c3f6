// AVX-512 helpers of the packet traversal (16 float lanes): min/max,
// reductions over lanes and gathers, written with the mask intrinsics so that
// g++ 12 sees no undefined pass-through operand.
#pragma once

#if defined(__AVX512F__)

#include <immintrin.h>

#include <limits>

#include "core/force_inline.h"
#include "core/min_max16.h"

namespace hprt::detail {

// max16 / min16 (core/min_max16.h) are robust_max / robust_min with the slab
// value first.

// The smallest of the lanes of `m` (+inf for none), by shuffles (the mask
// variants, for the same reason as above); the greatest (-inf for none).
HPRT_FORCE_INLINE float masked_min16(__mmask16 m, __m512 v) {
  v = _mm512_mask_mov_ps(_mm512_set1_ps(std::numeric_limits<float>::infinity()), m, v);
  v = min16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0x4E));
  v = min16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0xB1));
  v = min16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0x4E));
  v = min16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0xB1));
  return _mm512_cvtss_f32(v);
}
HPRT_FORCE_INLINE float masked_max16(__mmask16 m, __m512 v) {
  v = _mm512_mask_mov_ps(_mm512_set1_ps(-std::numeric_limits<float>::infinity()), m, v);
  v = max16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0x4E));
  v = max16(v, _mm512_mask_shuffle_f32x4(v, 0xFFFF, v, v, 0xB1));
  v = max16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0x4E));
  v = max16(v, _mm512_mask_permute_ps(v, 0xFFFF, v, 0xB1));
  return _mm512_cvtss_f32(v);
}
// The least and the greatest lane.
HPRT_FORCE_INLINE float reduce_min16(__m512 v) { return masked_min16(0xFFFF, v); }
HPRT_FORCE_INLINE float reduce_max16(__m512 v) { return masked_max16(0xFFFF, v); }

}  // namespace hprt::detail

#endif  // __AVX512F__
