// Centroid binning shared by the binned (Algorithm 3) and parallel
// (Algorithm 5) builders (Wald 2007): the bin mapping, the per-axis bins, and
// the serial evaluation of the bins-1 cuts per axis from prefix/suffix sweeps.
// Bins merge with min/max and integer adds only, so any merge order gives the
// same bits; costs are computed serially from the merged bins.
#pragma once

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "bvh/input/box_ref.h"
#include "bvh/input/build_options.h"
#include "bvh/split/binned_sweep16.h"
#include "bvh/split/sah.h"
#include "core/aabb.h"

namespace hprt {

// bin(c) = clamp(int((c - cmin) * k), 0, bins - 1), k = bins * (1 - eps) / extent.
// An axis whose centroid extent is zero (or too small for a finite k) is skipped.
struct BinMapping {
  int bins = 0;
  float cmin[3] = {0, 0, 0};
  float k[3] = {0, 0, 0};
  bool usable[3] = {false, false, false};
  __m128 vcmin, vk;  // cmin and k as vectors (lane 3: 0)
  __m128 vlast;      // bins - 1 in every lane

  BinMapping(const AABB& centroid_bounds, int bin_count) : bins(bin_count) {
    constexpr float kEps = 1e-6f;
    for (int a = 0; a < 3; ++a) {
      const float lo = centroid_bounds.min[a];
      const float extent = centroid_bounds.max[a] - lo;
      const float scale = static_cast<float>(bin_count) * (1.0f - kEps) / extent;
      cmin[a] = lo;
      usable[a] = extent > 0.0f && std::isfinite(scale) && scale > 0.0f;
      k[a] = usable[a] ? scale : 0.0f;
    }
    vcmin = _mm_setr_ps(cmin[0], cmin[1], cmin[2], 0.0f);
    vk = _mm_setr_ps(k[0], k[1], k[2], 0.0f);
    vlast = _mm_set1_ps(static_cast<float>(bins - 1));
  }
  bool any_usable() const { return usable[0] || usable[1] || usable[2]; }
  int bin(float c, int axis) const {
    const int i = static_cast<int>((c - cmin[axis]) * k[axis]);
    return std::min(std::max(i, 0), bins - 1);
  }
  // bin() of the three lanes of centre c at once (an unusable axis gives 0).
  // Clamping before the truncation gives bin()'s result (NaN: max gives 0).
  __m128i bins_of(__m128 c) const {
    const __m128 x = _mm_mul_ps(_mm_sub_ps(c, vcmin), vk);
    return _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), vlast));
  }
};

// bins[axis * bin_count + b]: box and primitive count of bin b on that axis.
// Boxes are kept as lo and -hi vectors, so that extending one is a single
// (AVX: 8-wide) min; negation is exact, so the bits are those of lo/hi.
struct Bins {
  struct alignas(32) Box {
    __m128 lo, nhi;  // min.xyz, -max.xyz
  };
  int bin_count = 0;
  std::vector<Box> boxes;
  std::vector<uint32_t> counts;

  // Room for n bins per axis, all in use until reset(count) picks fewer.
  explicit Bins(int n = 0) : bin_count(n), boxes(3 * size_t(n)), counts(3 * size_t(n), 0) {
    reset(n);
  }
  void reset(int count) {
    bin_count = count;
    std::fill_n(boxes.begin(), 3 * size_t(count), empty_box());
    std::fill_n(counts.begin(), 3 * size_t(count), 0u);
  }
  static Box empty_box() {
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    return {inf, inf};
  }
  static __m128 neg(__m128 v) { return _mm_xor_ps(v, _mm_set1_ps(-0.0f)); }
  static AABB to_aabb(const Box& b) { return vec_to_aabb(b.lo, neg(b.nhi)); }
  static float half_area(const Box& b) { return vec_half_area(b.lo, neg(b.nhi)); }
  static void extend(Box& d, const Box& b) {
    d.lo = _mm_min_ps(d.lo, b.lo);
    d.nhi = _mm_min_ps(d.nhi, b.nhi);
  }
  AABB box(size_t i) const { return to_aabb(boxes[i]); }
  // Adds one primitive to its bin on every axis (unusable axes: bin 0, never read).
  void add(const BinMapping& m, const BoxRef& r) {
    alignas(16) int idx[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(idx), m.bins_of(r.center()));
    const int n = bin_count;
    const Box rb{r.lo, neg(r.hi)};
    for (int a = 0; a < 3; ++a) {
      extend(boxes[size_t(a * n + idx[a])], rb);
      ++counts[size_t(a * n + idx[a])];
    }
  }
  // The same for a box b whose centre is c (c == b.center()).
  void add(const BinMapping& m, const AABB& b, const Vec3f& c) {
    (void)c;
    add(m, make_box_ref(b, 0));
  }
  void merge(const Bins& o) {
    for (size_t i = 0; i < 3 * size_t(bin_count); ++i) {
      extend(boxes[i], o.boxes[i]);
      counts[i] += o.counts[i];
    }
  }
};

// Adds refs[0, n) to `bins` (reset to m.bins bins). From kTwoBinSetsMin on,
// alternate primitives go through `spare` (merged at the end) so that runs of
// primitives in the same bin do not each wait for the previous update.
inline constexpr size_t kTwoBinSetsMin = 128;

inline void bin_refs(const BinMapping& m, const BoxRef* refs, size_t n, Bins& bins, Bins& spare) {
  bins.reset(m.bins);
  const size_t stride = size_t(m.bins);
  auto add = [&](Bins::Box* box, uint32_t* cnt, const BoxRef& r) {
    alignas(16) int idx[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(idx), m.bins_of(r.center()));
#if defined(__AVX__)
    const __m256 rb = _mm256_insertf128_ps(_mm256_castps128_ps256(r.lo), Bins::neg(r.hi), 1);
    for (size_t a = 0; a < 3; ++a) {
      float* b = reinterpret_cast<float*>(&box[a * stride + size_t(idx[a])]);
      _mm256_store_ps(b, _mm256_min_ps(_mm256_load_ps(b), rb));
      ++cnt[a * stride + size_t(idx[a])];
    }
#else
    const Bins::Box rb{r.lo, Bins::neg(r.hi)};
    for (size_t a = 0; a < 3; ++a) {
      Bins::extend(box[a * stride + size_t(idx[a])], rb);
      ++cnt[a * stride + size_t(idx[a])];
    }
#endif
  };
  Bins::Box* box0 = bins.boxes.data();
  uint32_t* cnt0 = bins.counts.data();
  if (n < kTwoBinSetsMin) {
    for (size_t i = 0; i < n; ++i) add(box0, cnt0, refs[i]);
    return;
  }
  spare.reset(m.bins);
  Bins::Box* box1 = spare.boxes.data();
  uint32_t* cnt1 = spare.counts.data();
  size_t i = 0;
  for (; i + 1 < n; i += 2) {
    add(box0, cnt0, refs[i]);
    add(box1, cnt1, refs[i + 1]);
  }
  if (i < n) add(box0, cnt0, refs[i]);
  bins.merge(spare);
}

// Bins per axis for a node of n primitives: at most max_bins, fewer for small
// nodes (4 + n / 20, as Embree's binned builders).
inline int bins_for(size_t n, int max_bins) {
  return static_cast<int>(std::min(static_cast<size_t>(max_bins), 4 + n / 20));
}

// The best binned cut: left = bins [0, cut] on `axis`. axis < 0: none found.
struct BinnedSplit {
  int axis = -1;
  int cut = -1;
  float cost = kNoSplit;
  AABB left_bounds, right_bounds;
  uint32_t left_count = 0, right_count = 0;
};

// binned_sweep16.h reads a box as 8 floats: lo xyz, pad, -hi xyz, pad.
static_assert(sizeof(Bins::Box) == 8 * sizeof(float));

namespace detail {

// The scalar sweep of one axis, with binned_sweep16.h's contract: prices the
// cuts of `bin_count` bins and keeps the cheapest below best.cost (ties: the
// lowest cut). `area`, `count`: scratch for the suffix areas and counts.
inline void sweep_axis_scalar(const Bins::Box* box, const uint32_t* cnt, int n,
                              const SahParams& sah, float parent_area, int axis, int& best_axis,
                              AxisCut& best, std::vector<float>& area,
                              std::vector<uint32_t>& count) {
  area.resize(size_t(n));
  count.resize(size_t(n));
  Bins::Box acc = Bins::empty_box();
  uint32_t acc_n = 0;
  for (int b = n - 1; b > 0; --b) {  // suffix: bins [b, n)
    Bins::extend(acc, box[b]);
    acc_n += cnt[b];
    // An empty bin leaves the suffix box as it was: reuse its area.
    area[size_t(b)] = cnt[b] ? Bins::half_area(acc) : (b + 1 < n ? area[size_t(b) + 1] : 0.0f);
    count[size_t(b)] = acc_n;
  }
  Bins::Box left = Bins::empty_box();
  uint32_t left_n = 0;
  for (int c = 0; c < n - 1; ++c) {  // cut after bin c
    Bins::extend(left, box[c]);
    left_n += cnt[c];
    const uint32_t right_n = count[size_t(c) + 1];
    if (left_n == 0 || right_n == 0) continue;
    // A run of empty bins prices the same cut as the occupied bin before it
    // (and ties keep the lowest cut), so only cuts after occupied bins count.
    if (cnt[c] == 0) continue;
    const float cost = sah_split_cost(sah, parent_area, Bins::half_area(left), left_n,
                                      area[size_t(c) + 1], right_n);
    if (cost < best.cost) {
      best_axis = axis;
      best.cut = c;
      best.cost = cost;
      best.left_count = left_n;
      best.right_count = right_n;
    }
  }
}

// Every usable axis through `sweep` (sweep_axis_scalar or sweep_axis16).
template <typename Sweep>
BinnedSplit find_binned_split_with(Sweep&& sweep, const Bins& bins, const BinMapping& m,
                                   const SahParams& sah, float parent_area,
                                   std::vector<float>& scratch_area,
                                   std::vector<uint32_t>& scratch_count) {
  BinnedSplit best;
  AxisCut cut;
  const int n = bins.bin_count;
  for (int a = 0; a < 3; ++a)
    if (m.usable[a])
      sweep(&bins.boxes[size_t(a) * n], &bins.counts[size_t(a) * n], n, sah, parent_area, a,
            best.axis, cut, scratch_area, scratch_count);
  if (best.axis >= 0) {  // child boxes: exact unions of the chosen bins
    best.cut = cut.cut;
    best.cost = cut.cost;
    best.left_count = cut.left_count;
    best.right_count = cut.right_count;
    for (int b = 0; b < n; ++b)
      (b <= best.cut ? best.left_bounds : best.right_bounds)
          .extend(bins.box(size_t(best.axis) * n + b));
  }
  return best;
}

}  // namespace detail

// Evaluates the bins-1 cuts of every usable axis; ties go to the lowest axis,
// then the lowest cut. `scratch` holds suffix areas/counts (reused, no
// allocation after the first call). With AVX-512, 16 cuts at a time
// (binned_sweep16.h), the same bits as the scalar sweep.
inline BinnedSplit find_binned_split(const Bins& bins, const BinMapping& m, const SahParams& sah,
                                     float parent_area, std::vector<float>& scratch_area,
                                     std::vector<uint32_t>& scratch_count) {
#ifdef HPRT_HAS_BINNED_SWEEP16
  const auto sweep = [](const Bins::Box* box, const uint32_t* cnt, auto&&... rest) {
    detail::sweep_axis16(reinterpret_cast<const float*>(box), cnt, rest...);
  };
#else
  const auto sweep = [](auto&&... args) { detail::sweep_axis_scalar(args...); };
#endif
  return detail::find_binned_split_with(sweep, bins, m, sah, parent_area, scratch_area,
                                        scratch_count);
}

// The same result as binning refs[0, n) and calling find_binned_split, bit for
// bit, without touching bins: per axis, sort the primitives by bin and price
// only the cuts right after an occupied bin (a cut inside a run of empty bins
// prices the same sets, and ties keep the lowest cut, which is that one).
// Cheaper than the bins when n is below the bin count (most nodes).
inline constexpr size_t kSmallNodeMax = 32;
inline constexpr int kCountingSortBins = 64;  // counting sort by bin up to this many bins

inline BinnedSplit find_binned_split_small(const BoxRef* refs, size_t n, const BinMapping& m,
                                           const SahParams& sah, float parent_area) {
  static_assert(kSmallNodeMax <= 32, "sort keys keep the local index in 5 bits");
  BinnedSplit best;
  // Bin per axis of every primitive; the three axes then work on these.
  const BoxRef* box = refs;
  uint16_t bin[3][kSmallNodeMax];
  for (size_t i = 0; i < n; ++i) {
    alignas(16) int idx[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(idx), m.bins_of(refs[i].center()));
    for (int a = 0; a < 3; ++a) bin[a][i] = static_cast<uint16_t>(idx[a]);
  }
  float right_area[kSmallNodeMax];
  for (int a = 0; a < 3; ++a) {
    if (!m.usable[a]) continue;
    // Key = bin * 32 + local index (bins <= 1024: fits 15 bits). Sorting the
    // keys orders by bin and, within a bin, by position: a stable sort by bin.
    uint16_t keys[kSmallNodeMax];
    if (n > 8 && m.bins <= kCountingSortBins) {  // counting sort (stable)
      uint8_t start[kCountingSortBins + 1] = {};
      for (size_t i = 0; i < n; ++i) ++start[bin[a][i] + 1];
      for (int b = 1; b < m.bins; ++b) start[b] = static_cast<uint8_t>(start[b] + start[b - 1]);
      for (size_t i = 0; i < n; ++i)
        keys[start[bin[a][i]]++] = static_cast<uint16_t>((bin[a][i] << 5) | i);
    } else {  // insertion sort of the keys
      for (size_t i = 0; i < n; ++i) {
        const uint16_t k = static_cast<uint16_t>((bin[a][i] << 5) | i);
        size_t j = i;
        for (; j > 0 && keys[j - 1] > k; --j) keys[j] = keys[j - 1];
        keys[j] = k;
      }
    }
    // Suffix areas, needed only where a new bin starts (keys[i] begins a bin).
    VecBox acc;
    for (size_t i = n - 1; i > 0; --i) {
      const BoxRef& b = box[keys[i] & 31];
      acc.extend(b.lo, b.hi);
      if ((keys[i] >> 5) != (keys[i - 1] >> 5)) right_area[i] = vec_half_area(acc.lo, acc.hi);
    }
    VecBox left;
    for (size_t i = 0; i + 1 < n; ++i) {
      const BoxRef& b = box[keys[i] & 31];
      left.extend(b.lo, b.hi);
      const int cut = keys[i] >> 5;
      if ((keys[i + 1] >> 5) == cut) continue;  // not the end of an occupied bin
      const float cost = sah_split_cost(sah, parent_area, vec_half_area(left.lo, left.hi),
                                        static_cast<uint32_t>(i + 1), right_area[i + 1],
                                        static_cast<uint32_t>(n - i - 1));
      if (cost < best.cost) {
        best.axis = a;
        best.cut = cut;
        best.cost = cost;
        best.left_count = static_cast<uint32_t>(i + 1);
        best.right_count = static_cast<uint32_t>(n - i - 1);
      }
    }
  }
  if (best.axis >= 0) {
    VecBox l, r;
    for (size_t i = 0; i < n; ++i)
      (bin[best.axis][i] <= best.cut ? l : r).extend(box[i].lo, box[i].hi);
    best.left_bounds = l.aabb();
    best.right_bounds = r.aabb();
  }
  return best;
}

}  // namespace hprt
