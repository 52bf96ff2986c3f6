// The partition step of the binned builders: refs go from one array to the
// other (the two swap roles each level), lefts packed from one cursor and
// rights from another, in input order (a stable partition), so no copy back.
#pragma once

#include <immintrin.h>

#include <cstddef>
#include <limits>

#include "bvh/input/box_ref.h"
#include "bvh/split/binning.h"

namespace hprt {

// Copies src[0, n) to left_out / right_out by the cut on axis A (left: bin <=
// cut) and extends lc / rc by the centres on each side. Returns the lefts.
template <int A>
size_t scatter_refs_axis(const BinMapping& m, int cut, const BoxRef* src, size_t n,
                         BoxRef* left_out, BoxRef* right_out, VecBox& lc, VecBox& rc) {
  const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
  const __m128 ninf = _mm_sub_ps(_mm_setzero_ps(), inf);
  const __m128i vcut = _mm_set1_epi32(cut);
  size_t nl = 0, nr = 0;
  for (size_t i = 0; i < n; ++i) {
    const BoxRef r = src[i];
    const __m128 c = r.center();
    // Every lane: bin(c[A]) > cut, i.e. the ref goes right.
    const __m128i right_i =
        _mm_shuffle_epi32(_mm_cmpgt_epi32(m.bins_of(c), vcut), _MM_SHUFFLE(A, A, A, A));
    const __m128 right = _mm_castsi128_ps(right_i);
    const size_t is_right = static_cast<size_t>(_mm_cvtsi128_si32(right_i)) & 1;
    (is_right ? right_out[nr] : left_out[nl]) = r;
    nl += 1 - is_right;
    nr += is_right;
    // The centre on its side, the empty value (inf / -inf) on the other.
    const __m128 cl = _mm_andnot_ps(right, c), cr = _mm_and_ps(right, c);
    lc.extend(_mm_or_ps(cl, _mm_and_ps(right, inf)), _mm_or_ps(cl, _mm_and_ps(right, ninf)));
    rc.extend(_mm_or_ps(cr, _mm_andnot_ps(right, inf)), _mm_or_ps(cr, _mm_andnot_ps(right, ninf)));
  }
  return nl;
}

inline size_t scatter_refs(int axis, const BinMapping& m, int cut, const BoxRef* src, size_t n,
                           BoxRef* left_out, BoxRef* right_out, VecBox& lc, VecBox& rc) {
  switch (axis) {
    case 0:
      return scatter_refs_axis<0>(m, cut, src, n, left_out, right_out, lc, rc);
    case 1:
      return scatter_refs_axis<1>(m, cut, src, n, left_out, right_out, lc, rc);
    default:
      return scatter_refs_axis<2>(m, cut, src, n, left_out, right_out, lc, rc);
  }
}

}  // namespace hprt
