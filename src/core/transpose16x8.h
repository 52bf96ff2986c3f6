// Sixteen records of 8 floats each (a ray, a bin's box) turned into eight
// AVX-512 vectors, one per field, record l in lane l: eight plain loads and
// a transpose by permutes, where eight stride-8 gathers would each wait for
// all 16 of their loads.
#pragma once

#if defined(__AVX512F__)

#include <immintrin.h>

#include <array>

#include "core/force_inline.h"

namespace hprt {

namespace detail {

// The transpose as three stages of two-register permutes. A float of the
// records has a 3-bit register and a 4-bit lane index; each stage exchanges
// one register bit with one lane bit, so record r's field f moves from
// register r >> 1, lane 8 (r & 1) + f to register f, lane r. Stage s's
// permute for the output whose new register bit is `bit`, lane by lane: bit
// 4 picks the second source register, bits 0-3 the source lane.
template <int kStage, int kBit>
constexpr std::array<int, 16> record_transpose_index() {
  std::array<int, 16> idx{};
  for (int lane = 0; lane < 16; ++lane) {
    const int b0 = lane & 1, b1 = (lane >> 1) & 1, b2 = (lane >> 2) & 1, b3 = lane >> 3;
    if constexpr (kStage == 0)  // lane (r0 f2 f1 f0) -> (r0 f2 f1 r1): r1 into the lane
      idx[lane] = b0 << 4 | b3 << 3 | b2 << 2 | b1 << 1 | kBit;
    else if constexpr (kStage == 1)  // -> (r0 f2 r2 r1): r2 in, f1 out
      idx[lane] = b1 << 4 | b3 << 3 | b2 << 2 | kBit << 1 | b0;
    else  // -> (r3 r2 r1 r0), the record index: r3 in, f2 out
      idx[lane] = b3 << 4 | b0 << 3 | kBit << 2 | b2 << 1 | b1;
  }
  return idx;
}

template <int kStage, int kBit>
HPRT_FORCE_INLINE __m512i record_transpose_vector() {
  static constexpr std::array<int, 16> kIdx = record_transpose_index<kStage, kBit>();
  return _mm512_loadu_si512(kIdx.data());
}

}  // namespace detail

// a[j]: records 2j (lanes 0-7) and 2j + 1 (lanes 8-15), as one load of 16
// floats reads them. out[k] = field k of records 0..16, record l in lane l.
// `a` is overwritten.
HPRT_FORCE_INLINE void transpose_records16(__m512 a[8], __m512 out[8]) {
  __m512 b[8];
  // Stage 0: registers (r3 r2 r1) -> (r3 r2 f0).
  for (int m = 0; m < 4; ++m) {
    b[2 * m] =
        _mm512_permutex2var_ps(a[2 * m], detail::record_transpose_vector<0, 0>(), a[2 * m + 1]);
    b[2 * m + 1] =
        _mm512_permutex2var_ps(a[2 * m], detail::record_transpose_vector<0, 1>(), a[2 * m + 1]);
  }
  // Stage 1: (r3 r2 f0) -> (r3 f1 f0).
  for (int r3 = 0; r3 < 2; ++r3)
    for (int f0 = 0; f0 < 2; ++f0) {
      const __m512 lo = b[4 * r3 + f0], hi = b[4 * r3 + 2 + f0];
      a[4 * r3 + f0] = _mm512_permutex2var_ps(lo, detail::record_transpose_vector<1, 0>(), hi);
      a[4 * r3 + 2 + f0] = _mm512_permutex2var_ps(lo, detail::record_transpose_vector<1, 1>(), hi);
    }
  // Stage 2: (r3 f1 f0) -> (f2 f1 f0), lanes in record order.
  for (int k = 0; k < 4; ++k) {
    out[k] = _mm512_permutex2var_ps(a[k], detail::record_transpose_vector<2, 0>(), a[4 + k]);
    out[4 + k] = _mm512_permutex2var_ps(a[k], detail::record_transpose_vector<2, 1>(), a[4 + k]);
  }
}

}  // namespace hprt

#endif  // __AVX512F__
