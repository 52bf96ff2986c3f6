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

#include "bvh/build_options.h"
#include "bvh/sah.h"
#include "core/aabb.h"

namespace hprt {

// bin(c) = clamp(int((c - cmin) * k), 0, bins - 1), k = bins * (1 - eps) / extent.
// An axis whose centroid extent is zero (or too small for a finite k) is skipped.
struct BinMapping {
  int bins = 0;
  float cmin[3] = {0, 0, 0};
  float k[3] = {0, 0, 0};
  bool usable[3] = {false, false, false};

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
  }
  bool any_usable() const { return usable[0] || usable[1] || usable[2]; }
  int bin(float c, int axis) const {
    const int i = static_cast<int>((c - cmin[axis]) * k[axis]);
    return std::min(std::max(i, 0), bins - 1);
  }
};

// bins[axis * bin_count + b]: box and primitive count of bin b on that axis.
// Boxes are kept as 4-wide lo/hi vectors (SSE min/max per primitive).
struct Bins {
  struct alignas(16) Box {
    __m128 lo, hi;
  };
  int bin_count = 0;
  std::vector<Box> boxes;
  std::vector<uint32_t> counts;

  explicit Bins(int n = 0) : bin_count(n), boxes(3 * size_t(n)), counts(3 * size_t(n), 0) {
    reset();
  }
  void reset() {
    const Box empty{_mm_set1_ps(std::numeric_limits<float>::infinity()),
                    _mm_set1_ps(-std::numeric_limits<float>::infinity())};
    std::fill(boxes.begin(), boxes.end(), empty);
    std::fill(counts.begin(), counts.end(), 0u);
  }
  static Box empty_box() {
    return {_mm_set1_ps(std::numeric_limits<float>::infinity()),
            _mm_set1_ps(-std::numeric_limits<float>::infinity())};
  }
  static AABB to_aabb(const Box& b) {
    alignas(16) float lo[4], hi[4];
    _mm_store_ps(lo, b.lo);
    _mm_store_ps(hi, b.hi);
    return AABB({lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]});
  }
  AABB box(size_t i) const { return to_aabb(boxes[i]); }
  // An AABB as lo/hi vectors. Both loads stay inside the 24-byte box: lanes
  // min.xyz and (min.z, max.xyz) shuffled to max.xyz.
  static Box load_box(const AABB& b) {
    const __m128 hi = _mm_loadu_ps(&b.min.z);
    return {_mm_loadu_ps(&b.min.x), _mm_shuffle_ps(hi, hi, _MM_SHUFFLE(3, 3, 2, 1))};
  }
  // Adds one primitive (box b, centroid c) to its bin on every usable axis.
  void add(const BinMapping& m, const AABB& b, const Vec3f& c) {
    // Both loads stay inside the 24-byte box: lanes min.xyz and (min.z, max.xyz).
    const __m128 lo = _mm_loadu_ps(&b.min.x);
    const __m128 hi =
        _mm_shuffle_ps(_mm_loadu_ps(&b.min.z), _mm_loadu_ps(&b.min.z), _MM_SHUFFLE(3, 3, 2, 1));
    const int n = bin_count;
    if (m.usable[0]) extend(m.bin(c.x, 0), lo, hi);
    if (m.usable[1]) extend(n + m.bin(c.y, 1), lo, hi);
    if (m.usable[2]) extend(2 * n + m.bin(c.z, 2), lo, hi);
  }
  void merge(const Bins& o) {
    for (size_t i = 0; i < boxes.size(); ++i) {
      boxes[i].lo = _mm_min_ps(boxes[i].lo, o.boxes[i].lo);
      boxes[i].hi = _mm_max_ps(boxes[i].hi, o.boxes[i].hi);
      counts[i] += o.counts[i];
    }
  }

 private:
  void extend(int i, __m128 lo, __m128 hi) {
    boxes[i].lo = _mm_min_ps(boxes[i].lo, lo);
    boxes[i].hi = _mm_max_ps(boxes[i].hi, hi);
    ++counts[i];
  }
};

// The best binned cut: left = bins [0, cut] on `axis`. axis < 0: none found.
struct BinnedSplit {
  int axis = -1;
  int cut = -1;
  float cost = kNoSplit;
  AABB left_bounds, right_bounds;
  uint32_t left_count = 0, right_count = 0;
};

// Evaluates the bins-1 cuts of every usable axis; ties go to the lowest axis,
// then the lowest cut. `scratch` holds suffix areas/counts (reused, no
// allocation after the first call).
inline BinnedSplit find_binned_split(const Bins& bins, const BinMapping& m, const SahParams& sah,
                                     float parent_area, std::vector<float>& scratch_area,
                                     std::vector<uint32_t>& scratch_count) {
  BinnedSplit best;
  const int n = bins.bin_count;
  scratch_area.resize(n);
  scratch_count.resize(n);
  for (int a = 0; a < 3; ++a) {
    if (!m.usable[a]) continue;
    const Bins::Box* box = &bins.boxes[size_t(a) * n];
    const uint32_t* cnt = &bins.counts[size_t(a) * n];
    Bins::Box acc = Bins::empty_box();
    uint32_t acc_n = 0;
    for (int b = n - 1; b > 0; --b) {  // suffix: bins [b, n)
      acc.lo = _mm_min_ps(acc.lo, box[b].lo);
      acc.hi = _mm_max_ps(acc.hi, box[b].hi);
      acc_n += cnt[b];
      // An empty bin leaves the suffix box as it was: reuse its area.
      scratch_area[b] =
          cnt[b] ? Bins::to_aabb(acc).half_area() : (b + 1 < n ? scratch_area[b + 1] : 0.0f);
      scratch_count[b] = acc_n;
    }
    Bins::Box left = Bins::empty_box();
    uint32_t left_n = 0;
    for (int c = 0; c < n - 1; ++c) {  // cut after bin c
      left.lo = _mm_min_ps(left.lo, box[c].lo);
      left.hi = _mm_max_ps(left.hi, box[c].hi);
      left_n += cnt[c];
      const uint32_t right_n = scratch_count[c + 1];
      if (left_n == 0 || right_n == 0) continue;
      // A run of empty bins prices the same cut as the occupied bin before it
      // (and ties keep the lowest cut), so only cuts after occupied bins count.
      if (cnt[c] == 0) continue;
      const float cost = sah_split_cost(sah, parent_area, Bins::to_aabb(left).half_area(), left_n,
                                        scratch_area[c + 1], right_n);
      if (cost < best.cost) {
        best.axis = a;
        best.cut = c;
        best.cost = cost;
        best.left_count = left_n;
        best.right_count = right_n;
      }
    }
  }
  if (best.axis >= 0) {  // child boxes: exact unions of the chosen bins
    for (int b = 0; b < n; ++b)
      (b <= best.cut ? best.left_bounds : best.right_bounds)
          .extend(bins.box(size_t(best.axis) * n + b));
  }
  return best;
}

// The same result as binning ids[0, n) and calling find_binned_split, bit for
// bit, without touching bins: per axis, sort the primitives by bin and price
// only the cuts right after an occupied bin (a cut inside a run of empty bins
// prices the same sets, and ties keep the lowest cut, which is that one).
// Cheaper than the bins when n is below the bin count (most nodes).
inline constexpr size_t kSmallNodeMax = 32;
inline constexpr int kCountingSortBins = 64;  // counting sort by bin up to this many bins

inline BinnedSplit find_binned_split_small(const AABB* prim_bounds, const Vec3f* centroids,
                                           const uint32_t* ids, size_t n, const BinMapping& m,
                                           const SahParams& sah, float parent_area) {
  static_assert(kSmallNodeMax <= 32, "sort keys keep the local index in 5 bits");
  BinnedSplit best;
  // One gather per primitive (box as SSE lo/hi, bin per axis); the three axes
  // then work on these local copies only.
  Bins::Box box[kSmallNodeMax];
  uint16_t bin[3][kSmallNodeMax];
  for (size_t i = 0; i < n; ++i) {
    const uint32_t id = ids[i];
    box[i] = Bins::load_box(prim_bounds[id]);
    const Vec3f& c = centroids[id];
    for (int a = 0; a < 3; ++a) bin[a][i] = static_cast<uint16_t>(m.usable[a] ? m.bin(c[a], a) : 0);
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
    Bins::Box acc = Bins::empty_box();
    for (size_t i = n - 1; i > 0; --i) {
      const Bins::Box& b = box[keys[i] & 31];
      acc.lo = _mm_min_ps(acc.lo, b.lo);
      acc.hi = _mm_max_ps(acc.hi, b.hi);
      if ((keys[i] >> 5) != (keys[i - 1] >> 5)) right_area[i] = Bins::to_aabb(acc).half_area();
    }
    Bins::Box left = Bins::empty_box();
    for (size_t i = 0; i + 1 < n; ++i) {
      const Bins::Box& b = box[keys[i] & 31];
      left.lo = _mm_min_ps(left.lo, b.lo);
      left.hi = _mm_max_ps(left.hi, b.hi);
      const int cut = keys[i] >> 5;
      if ((keys[i + 1] >> 5) == cut) continue;  // not the end of an occupied bin
      const float cost = sah_split_cost(sah, parent_area, Bins::to_aabb(left).half_area(),
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
    Bins::Box l = Bins::empty_box(), r = Bins::empty_box();
    for (size_t i = 0; i < n; ++i) {
      Bins::Box& d = bin[best.axis][i] <= best.cut ? l : r;
      d.lo = _mm_min_ps(d.lo, box[i].lo);
      d.hi = _mm_max_ps(d.hi, box[i].hi);
    }
    best.left_bounds = Bins::to_aabb(l);
    best.right_bounds = Bins::to_aabb(r);
  }
  return best;
}

}  // namespace hprt
