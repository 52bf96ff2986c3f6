// Per-lane min and max of 16 floats with hprt::min/max's rule (`a < b ? a :
// b`, `a > b ? a : b`: on equal lanes, signed zeros included, b), as the
// mask forms of the intrinsics: the plain _mm512_min_ps/_mm512_max_ps pass an
// undefined operand that g++ 12 reports as maybe-uninitialized.
#pragma once

#if defined(__AVX512F__)

#include <immintrin.h>

#include "core/force_inline.h"

namespace hprt::detail {

HPRT_FORCE_INLINE __m512 max16(__m512 a, __m512 b) { return _mm512_mask_max_ps(b, 0xFFFF, a, b); }
HPRT_FORCE_INLINE __m512 min16(__m512 a, __m512 b) { return _mm512_mask_min_ps(b, 0xFFFF, a, b); }

}  // namespace hprt::detail

#endif
