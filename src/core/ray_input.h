// Rays as the caller holds them: Ray records, or six floats each (origin,
// direction: the layout of numpy and Open3D users' (N, 6) arrays) with one
// [tnear, tfar] for all. A batch reads them a block at a time (block()), so
// the six-float form is traced without first copying the whole batch into
// records: each block is converted into a small buffer that stays in L1.
#pragma once

#include <concepts>
#include <cstddef>
#include <ranges>
#include <span>
#include <stdexcept>

#include "core/ray.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace hprt {

class RayInput {
 public:
  // Any contiguous range of records (a span, a vector), read in place.
  template <std::ranges::contiguous_range R>
  requires std::same_as<std::ranges::range_value_t<R>, Ray> RayInput(const R& records)
      : records_(std::ranges::data(records)), size_(std::ranges::size(records)) {}
  // six.size() must be a multiple of 6.
  RayInput(std::span<const float> six, float tnear, float tfar)
      : six_(six.data()), size_(six.size() / 6), tnear_(tnear), tfar_(tfar) {
    if (six.size() % 6 != 0) throw std::invalid_argument("rays: not 6 floats per ray");
  }

  size_t size() const { return size_; }
  // The records when the rays are records, else null.
  const Ray* records() const { return records_; }

  // Ray i as a record.
  Ray operator[](size_t i) const {
    if (records_) return records_[i];
    const float* q = six_ + 6 * i;
    return Ray{{q[0], q[1], q[2]}, tnear_, {q[3], q[4], q[5]}, tfar_};
  }

  // Rays [first, first + n) as records: in place, or written into buf (n slots).
  const Ray* block(size_t first, size_t n, Ray* buf) const {
    if (records_) return records_ + first;
    size_t i = 0;
#if defined(__AVX512F__)
    const float* r = six_ + 6 * first;
    // Two rays per step: 12 floats spread over two records, the interval
    // kept in the other lanes (about a tenth of the scalar loop's loads and stores).
    const __m512i spread = _mm512_setr_epi32(0, 1, 2, 0, 3, 4, 5, 0, 6, 7, 8, 0, 9, 10, 11, 0);
    const __m512 interval =
        _mm512_setr_ps(0, 0, 0, tnear_, 0, 0, 0, tfar_, 0, 0, 0, tnear_, 0, 0, 0, tfar_);
    for (; i + 2 <= n; i += 2) {
      // A plain load reads 4 floats past the pair: of the next ray, where one follows.
      const __m512 six = first + i + 3 <= size_ ? _mm512_loadu_ps(r + 6 * i)
                                                : _mm512_maskz_loadu_ps(0x0fff, r + 6 * i);
      _mm512_storeu_ps(reinterpret_cast<float*>(buf + i),
                       _mm512_mask_permutexvar_ps(interval, 0x7777, spread, six));
    }
#endif
    for (; i < n; ++i) buf[i] = (*this)[first + i];
    return buf;
  }

 private:
  const Ray* records_ = nullptr;
  const float* six_ = nullptr;
  size_t size_ = 0;
  float tnear_ = 0.0f;
  float tfar_ = 0.0f;
};

}  // namespace hprt
