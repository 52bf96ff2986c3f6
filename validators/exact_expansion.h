// Exact arithmetic on floating-point expansions of any length (Shewchuk, "Adaptive Precision
// Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997): a
// value is an unevaluated sum of non-overlapping doubles in increasing
// magnitude. Sums and products are exact while no component overflows or
// underflows (inputs here are floats: exact for |values| up to ~1e50 and well
// away from the denormal range). Needs IEEE double without fast-math.
#pragma once

#include <cmath>
#include <vector>

#include "core/exact_arith.h"

namespace hprt::exact {

class Expansion {
 public:
  Expansion() = default;
  explicit Expansion(double x) {
    if (x != 0.0) c_.push_back(x);
  }

  // Sign of the exact value: the sign of the largest (last) component.
  int sign() const { return c_.empty() ? 0 : (c_.back() > 0.0 ? 1 : -1); }
  // An approximation of the value (summed from the smallest component up).
  double estimate() const {
    double s = 0.0;
    for (double x : c_) s += x;
    return s;
  }
  const std::vector<double>& components() const { return c_; }

  friend Expansion operator+(const Expansion& a, const Expansion& b) {
    Expansion r = a;
    for (double x : b.c_) r.grow(x);
    return r;
  }
  friend Expansion operator-(const Expansion& a) {
    Expansion r = a;
    for (double& x : r.c_) x = -x;
    return r;
  }
  friend Expansion operator-(const Expansion& a, const Expansion& b) { return a + (-b); }
  friend Expansion operator*(const Expansion& a, const Expansion& b) {
    Expansion r;
    for (double x : b.c_) r = r + a.scaled(x);
    return r;
  }

 private:
  // Grow-Expansion with zero elimination: this += b.
  void grow(double b) {
    std::vector<double> out;
    out.reserve(c_.size() + 1);
    double q = b;
    for (double e : c_) {
      double h;
      two_sum(q, e, q, h);
      if (h != 0.0) out.push_back(h);
    }
    if (q != 0.0) out.push_back(q);
    c_ = std::move(out);
  }
  // Scale-Expansion with zero elimination: this * b.
  Expansion scaled(double b) const {
    Expansion r;
    if (c_.empty() || b == 0.0) return r;
    r.c_.reserve(2 * c_.size());
    double q, h;
    two_product(c_[0], b, q, h);
    if (h != 0.0) r.c_.push_back(h);
    for (size_t i = 1; i < c_.size(); ++i) {
      double p1, p0, s;
      two_product(c_[i], b, p1, p0);
      two_sum(q, p0, s, h);
      if (h != 0.0) r.c_.push_back(h);
      two_sum(p1, s, q, h);  // p1 >= s in magnitude: Fast-Two-Sum would do
      if (h != 0.0) r.c_.push_back(h);
    }
    if (q != 0.0) r.c_.push_back(q);
    return r;
  }

  std::vector<double> c_;
};

// a - b exactly, for doubles.
inline Expansion diff(double a, double b) { return Expansion(a) - Expansion(b); }

}  // namespace hprt::exact
