// A std::vector that may instead view an array its caller owns: the public
// API's shared meshes (Scene::add_mesh_shared) keep the caller's vertex and
// index arrays without a copy. Reads go to the view; the first write through
// a non-const accessor copies it (copy on write), so code written for
// std::vector works unchanged and never writes into the caller's memory.
#pragma once

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <utility>
#include <vector>

namespace hprt {

template <typename T>
class SharedArray {
 public:
  using value_type = T;
  using size_type = size_t;
  using iterator = T*;
  using const_iterator = const T*;
  using reference = T&;
  using const_reference = const T&;

  SharedArray() = default;
  SharedArray(std::initializer_list<T> values) : own_(values) {}
  SharedArray(std::vector<T> values) : own_(std::move(values)) {}  // NOLINT: implicit, as a vector
  SharedArray(size_t n, const T& value) : own_(n, value) {}
  explicit SharedArray(size_t n) : own_(n) {}

  // A view of n elements at data, which must outlive every read.
  static SharedArray view(const T* data, size_t n) {
    SharedArray a;
    a.view_ = data;
    a.view_size_ = n;
    return a;
  }
  bool is_view() const { return view_ != nullptr; }

  size_t size() const { return view_ ? view_size_ : own_.size(); }
  bool empty() const { return size() == 0; }
  // A view has no spare capacity (TriangleMesh::padded_for_embree()).
  size_t capacity() const { return view_ ? view_size_ : own_.capacity(); }

  const T* data() const { return view_ ? view_ : own_.data(); }
  const T& operator[](size_t i) const { return data()[i]; }
  const T* begin() const { return data(); }
  const T* end() const { return data() + size(); }
  const T* cbegin() const { return begin(); }
  const T* cend() const { return end(); }
  const T& front() const { return data()[0]; }
  const T& back() const { return data()[size() - 1]; }

  T* data() { return own().data(); }
  T& operator[](size_t i) { return own()[i]; }
  T* begin() { return own().data(); }
  T* end() { return own().data() + own_.size(); }
  T& front() { return own().front(); }
  T& back() { return own().back(); }

  void reserve(size_t n) { own().reserve(n); }
  void resize(size_t n) { own().resize(n); }
  void resize(size_t n, const T& value) { own().resize(n, value); }
  void push_back(const T& value) { own().push_back(value); }
  void assign(const T* first, const T* last) {
    clear();
    own_.assign(first, last);
  }
  void pop_back() { own().pop_back(); }
  template <typename... Args>
  T& emplace_back(Args&&... args) {
    return own().emplace_back(std::forward<Args>(args)...);
  }
  void clear() {
    view_ = nullptr;
    view_size_ = 0;
    own_.clear();
  }
  void shrink_to_fit() { own().shrink_to_fit(); }

  std::vector<T> to_vector() const { return std::vector<T>(begin(), end()); }

  friend bool operator==(const SharedArray& a, const SharedArray& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
  }
  friend bool operator==(const SharedArray& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
  }

 private:
  // The owned vector, after copying the view into it if there is one.
  std::vector<T>& own() {
    if (view_) {
      own_.assign(view_, view_ + view_size_);
      view_ = nullptr;
      view_size_ = 0;
    }
    return own_;
  }

  std::vector<T> own_;
  const T* view_ = nullptr;
  size_t view_size_ = 0;
};

}  // namespace hprt
