// A fixed-size array for the traversal layouts' large arrays: allocated
// uninitialised (make_huge_buffer: huge-page advised when large), so each page
// is first touched by the parallel loop that fills it instead of being zeroed
// on one thread by std::vector::resize and then written again. Copies are
// deep. T must be trivially copyable.
#pragma once

#include <algorithm>
#include <cstddef>

#include "bvh/memory/huge_buffer.h"

namespace hprt {

template <typename T>
class BuildArray {
 public:
  BuildArray() = default;
  explicit BuildArray(size_t n) : data_(n ? make_huge_buffer<T>(n) : nullptr), size_(n) {}
  BuildArray(const BuildArray& o) : BuildArray(o.size_) { std::copy(o.begin(), o.end(), begin()); }
  BuildArray(BuildArray&&) noexcept = default;
  BuildArray& operator=(const BuildArray& o) {
    if (this != &o) *this = BuildArray(o);
    return *this;
  }
  BuildArray& operator=(BuildArray&& o) noexcept {
    data_ = std::move(o.data_);
    size_ = o.size_;
    o.size_ = 0;
    return *this;
  }

  // n elements, contents unspecified: the storage is kept when the size is
  // unchanged (a rebuild of a deforming mesh writes the same arrays again
  // instead of faulting in fresh pages), else allocated anew.
  void reset(size_t n) {
    if (n != size_) *this = BuildArray(n);
  }

  // Keeps the first n <= size() elements (and the storage).
  void shrink(size_t n) { size_ = n < size_ ? n : size_; }

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_.get(); }
  const T* data() const { return data_.get(); }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  T* begin() { return data(); }
  T* end() { return data() + size_; }
  const T* begin() const { return data(); }
  const T* end() const { return data() + size_; }

  bool operator==(const BuildArray& o) const {
    return size_ == o.size_ && std::equal(begin(), end(), o.begin());
  }

 private:
  HugeBuffer<T> data_;
  size_t size_ = 0;
};

}  // namespace hprt
