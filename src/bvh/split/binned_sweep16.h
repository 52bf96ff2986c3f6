// The bins-1 cuts of one axis priced 16 bins at a time (AVX-512): the
// prefix and suffix boxes by log-step scans across lanes, their areas and
// SAH costs one lane per cut. The scalar sweep of find_binned_split
// (binning.h) spends most of its time in the latency of one half area per
// bin and one cost per cut; here the 32 bins of a large node take two
// vectors. Every lane computes what the scalar sweep computes for its cut,
// with the same operations in the same order (min is exact; the products
// of a half area are kept unfused as vec_half_area keeps them; the cost
// uses the fused multiply-adds of sah_mul_add), so both give the same bits.
#pragma once

#include <immintrin.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "bvh/input/build_options.h"
#include "bvh/split/sah.h"
#include "core/min_max16.h"
#include "core/transpose16x8.h"

namespace hprt::detail {

// The best cut of one axis so far: bins [0, cut] left.
struct AxisCut {
  int cut = -1;
  float cost = kNoSplit;
  uint32_t left_count = 0, right_count = 0;
};

}  // namespace hprt::detail

#if defined(__AVX512F__) && defined(__FMA__)
#define HPRT_HAS_BINNED_SWEEP16 1

namespace hprt::detail {

// Boxes of up to 16 bins as six lane vectors: lo.x, lo.y, lo.z and
// -hi.x, -hi.y, -hi.z (the Bins::Box layout: lo xyz, pad, -hi xyz, pad, 8
// floats per bin). Lanes from `count` on are empty boxes with count 0.
struct BinLanes {
  __m512 c[6];
  __m512i n;

  BinLanes() : n(_mm512_setzero_si512()) {  // empty boxes, no primitives
    for (__m512& v : c) v = _mm512_set1_ps(std::numeric_limits<float>::infinity());
  }
  BinLanes(const float* boxes, const uint32_t* counts, int count) {
    const __mmask16 live = count >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << count) - 1);
    __m512 a[8], f[8];
    for (int j = 0; j < 8; ++j) {  // bins 2j, 2j + 1; none read past `count`
      const __mmask16 m =
          __mmask16((2 * j < count ? 0x00FF : 0) | (2 * j + 1 < count ? 0xFF00 : 0));
      a[j] = _mm512_maskz_loadu_ps(m, boxes + 16 * j);
    }
    transpose_records16(a, f);
    const __m512 empty = _mm512_set1_ps(std::numeric_limits<float>::infinity());
    constexpr int kField[6] = {0, 1, 2, 4, 5, 6};
    for (int k = 0; k < 6; ++k) c[k] = _mm512_mask_mov_ps(empty, live, f[kField[k]]);
    n = _mm512_maskz_loadu_epi32(live, counts);
  }
};

// The plain 512-bit min, align, permute and conversion pass an undefined
// operand that g++ 12 reports as maybe-uninitialized: their mask variants
// (min16 and max16 in core/min_max16.h).
template <int Imm>
inline __m512i align16(__m512i hi, __m512i lo) {
  return _mm512_mask_alignr_epi32(lo, 0xFFFF, hi, lo, Imm);
}

// Lane i of the result: v[i - s] (s = 1, 2, 4, 8), `fill` below s.
template <int S>
inline __m512i lanes_up(__m512i v, __m512i fill) {
  return align16<16 - S>(v, fill);
}
// Lane i: v[i + s], `fill` from 16 - s on.
template <int S>
inline __m512i lanes_down(__m512i v, __m512i fill) {
  return align16<S>(fill, v);
}

// In-lane inclusive scans: prefix (lane i over lanes 0..i) or suffix (over
// i..15), each then combined with `carry` (the scan of the bins before /
// after this vector, broadcast).
template <bool kPrefix>
inline void scan_lanes(BinLanes& b, const BinLanes& carry) {
  const __m512i empty = _mm512_castps_si512(_mm512_set1_ps(std::numeric_limits<float>::infinity()));
  const __m512i zero = _mm512_setzero_si512();
  const auto step = [&]<int S>() {
    for (int k = 0; k < 6; ++k) {
      const __m512i v = _mm512_castps_si512(b.c[k]);
      const __m512i o = kPrefix ? lanes_up<S>(v, empty) : lanes_down<S>(v, empty);
      b.c[k] = min16(b.c[k], _mm512_castsi512_ps(o));
    }
    b.n = _mm512_add_epi32(b.n, kPrefix ? lanes_up<S>(b.n, zero) : lanes_down<S>(b.n, zero));
  };
  step.template operator()<1>();
  step.template operator()<2>();
  step.template operator()<4>();
  step.template operator()<8>();
  for (int k = 0; k < 6; ++k) b.c[k] = min16(b.c[k], carry.c[k]);
  b.n = _mm512_add_epi32(b.n, carry.n);
}

// Every lane set to lane L of b.
template <int L>
inline BinLanes broadcast_lane(const BinLanes& b) {
  BinLanes out = b;
  const __m512i at = _mm512_set1_epi32(L);
  for (int k = 0; k < 6; ++k) out.c[k] = _mm512_mask_permutexvar_ps(b.c[k], 0xFFFF, at, b.c[k]);
  out.n = _mm512_mask_permutexvar_epi32(b.n, 0xFFFF, at, b.n);
  return out;
}

// vec_half_area per lane: (xy + yz) + zx of hi - lo, products unfused.
inline __m512 half_area16(const BinLanes& b) {
  const __m512i sign = _mm512_set1_epi32(int(0x80000000u));
  __m512 d[3];
  for (int k = 0; k < 3; ++k) {
    const __m512 hi = _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(b.c[3 + k]), sign));
    d[k] = _mm512_sub_ps(hi, b.c[k]);
  }
  __m512 xy = _mm512_mul_ps(d[0], d[1]), yz = _mm512_mul_ps(d[1], d[2]),
         zx = _mm512_mul_ps(d[2], d[0]);
  asm("" : "+v"(xy), "+v"(yz), "+v"(zx));
  return _mm512_add_ps(_mm512_add_ps(xy, yz), zx);
}

// sah_units per lane.
inline __m512 sah_units16(const SahParams& p, __m512i count) {
  if (p.leaf_block <= 1) return _mm512_mask_cvtepu32_ps(_mm512_setzero_ps(), 0xFFFF, count);
  alignas(64) uint32_t c[16];
  alignas(64) float u[16];
  _mm512_store_si512(c, count);
  for (int l = 0; l < 16; ++l) u[l] = sah_units(p, c[l]);
  return _mm512_load_ps(u);
}

// Prices the cuts of one axis of `bin_count` bins (boxes: 8 floats per bin,
// counts) and keeps the cheapest: the lowest cut among equal costs, and only
// a cost below `best.cost` (an earlier axis keeps its ties). A cut counts
// when it follows an occupied bin and leaves primitives on both sides.
// `area`, `count`: scratch, resized here.
inline void sweep_axis16(const float* boxes, const uint32_t* counts, int bin_count,
                         const SahParams& sah, float parent_area, int axis, int& best_axis,
                         AxisCut& best, std::vector<float>& area, std::vector<uint32_t>& count) {
  const int chunks = (bin_count + 15) / 16;
  area.resize(size_t(chunks) * 16 + 16);
  count.resize(size_t(chunks) * 16 + 16);
  // Suffix boxes (bins [b, n)): their areas and counts, last vector first.
  const auto load = [&](int k) {
    return BinLanes(boxes + 128 * k, counts + 16 * k, bin_count - 16 * k);
  };
  BinLanes kept[2];  // the first two vectors (32 bins, the default) are loaded once
  BinLanes carry;
  for (int k = chunks - 1; k >= 0; --k) {
    BinLanes s = load(k);
    if (k < 2) kept[k] = s;
    scan_lanes<false>(s, carry);
    _mm512_storeu_ps(&area[16 * size_t(k)], half_area16(s));
    _mm512_storeu_si512(&count[16 * size_t(k)], s.n);
    carry = broadcast_lane<0>(s);
  }
  const __m512 tc = _mm512_set1_ps(sah.traversal_cost), ic = _mm512_set1_ps(sah.intersection_cost);
  const __m512 pa = _mm512_set1_ps(parent_area);
  const __m512 none = _mm512_set1_ps(kNoSplit);
  carry = BinLanes();
  for (int k = 0; k < chunks; ++k) {
    BinLanes left = k < 2 ? kept[k] : load(k);
    const __m512i occupied = left.n;
    scan_lanes<true>(left, carry);
    carry = broadcast_lane<15>(left);
    // Cut c (bins [0, c] left) exists for c < bin_count - 1.
    const int cuts = bin_count - 1 - 16 * k;
    const __mmask16 live = cuts >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << cuts) - 1);
    const __m512 right_area = _mm512_maskz_loadu_ps(live, &area[16 * size_t(k) + 1]);
    const __m512i right_n = _mm512_maskz_loadu_epi32(live, &count[16 * size_t(k) + 1]);
    const __mmask16 priced = _mm512_mask_test_epi32_mask(live, occupied, occupied) &
                             _mm512_test_epi32_mask(left.n, left.n) &
                             _mm512_test_epi32_mask(right_n, right_n);
    if (!priced) continue;
    const __m512 children = _mm512_fmadd_ps(half_area16(left), sah_units16(sah, left.n),
                                            _mm512_mul_ps(right_area, sah_units16(sah, right_n)));
    const __m512 cost = _mm512_fmadd_ps(tc, pa, _mm512_mul_ps(ic, children));
    const __mmask16 valid = _mm512_mask_cmp_ps_mask(priced, cost, cost, _CMP_ORD_Q);
    __m512 m = _mm512_mask_blend_ps(valid, none, cost);  // the least valid cost, in every lane
    m = min16(m, _mm512_mask_shuffle_f32x4(m, 0xFFFF, m, m, 0x4E));
    m = min16(m, _mm512_mask_shuffle_f32x4(m, 0xFFFF, m, m, 0xB1));
    m = min16(m, _mm512_mask_permute_ps(m, 0xFFFF, m, 0x4E));
    m = min16(m, _mm512_mask_permute_ps(m, 0xFFFF, m, 0xB1));
    const float least = _mm512_cvtss_f32(m);
    if (!(least < best.cost)) continue;
    const int l = __builtin_ctz(_mm512_mask_cmp_ps_mask(valid, cost, m, _CMP_EQ_OQ));
    alignas(64) float c[16];
    alignas(64) uint32_t ln[16], rn[16];
    _mm512_store_ps(c, cost);
    _mm512_store_si512(ln, left.n);
    _mm512_store_si512(rn, right_n);
    best_axis = axis;
    best.cut = 16 * k + l;
    best.cost = c[l];
    best.left_count = ln[l];
    best.right_count = rn[l];
  }
}

}  // namespace hprt::detail

#endif
