// Error-free transformations and fixed-size floating-point expansions
// (Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
// Geometric Predicates", 1997): a value is an unevaluated sum of
// non-overlapping doubles in increasing magnitude, so its sign is the sign of
// its last component. FixedExpansion<N> holds at most N components on the
// stack: the exact fallback of the triangle test runs inside traversal, where
// nothing may allocate. Exact while no product underflows or overflows, which
// holds for any polynomial of degree <= 3 in floats (|x| <= 2^128, and the
// smallest non-zero term stays above 2^-900). Needs IEEE double without
// fast-math.
#pragma once

#include <cmath>

namespace hprt::exact {

// x + y = a + b exactly, x = fl(a + b) (Knuth's Two-Sum).
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

// x + y = a * b exactly, x = fl(a * b).
inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

template <int N>
struct FixedExpansion {
  static constexpr int kCapacity = N;
  double c[N];
  int n = 0;

  int sign() const { return n == 0 ? 0 : (c[n - 1] > 0.0 ? 1 : -1); }
  // The value to within about one ulp (summed from the smallest component).
  double estimate() const {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += c[i];
    return s;
  }
  // Grow-Expansion with zero elimination: this += b (needs n < N).
  void grow(double b) {
    double q = b;
    int out = 0;
    for (int i = 0; i < n; ++i) {
      double h;
      two_sum(q, c[i], q, h);
      if (h != 0.0) c[out++] = h;
    }
    if (q != 0.0) c[out++] = q;
    n = out;
  }
  template <int M>
  void add(const FixedExpansion<M>& b) {
    static_assert(M <= N);
    for (int i = 0; i < b.n; ++i) grow(b.c[i]);
  }
};

// a - b exactly.
inline FixedExpansion<2> subtract(double a, double b) {
  double x, y;
  two_sum(a, -b, x, y);
  FixedExpansion<2> r;
  if (y != 0.0) r.c[r.n++] = y;
  if (x != 0.0) r.c[r.n++] = x;
  return r;
}

// e * b exactly (Scale-Expansion with zero elimination).
template <int N>
FixedExpansion<2 * N> scale(const FixedExpansion<N>& e, double b) {
  FixedExpansion<2 * N> r;
  if (e.n == 0 || b == 0.0) return r;
  double q, h;
  two_product(e.c[0], b, q, h);
  if (h != 0.0) r.c[r.n++] = h;
  for (int i = 1; i < e.n; ++i) {
    double p1, p0, s;
    two_product(e.c[i], b, p1, p0);
    two_sum(q, p0, s, h);
    if (h != 0.0) r.c[r.n++] = h;
    two_sum(p1, s, q, h);
    if (h != 0.0) r.c[r.n++] = h;
  }
  if (q != 0.0) r.c[r.n++] = q;
  return r;
}

// a * b exactly.
template <int A, int B>
FixedExpansion<2 * A * B> product(const FixedExpansion<A>& a, const FixedExpansion<B>& b) {
  FixedExpansion<2 * A * B> r;
  for (int i = 0; i < b.n; ++i) r.add(scale(a, b.c[i]));
  return r;
}

// a + b, a - b exactly.
template <int A, int B>
FixedExpansion<A + B> sum(const FixedExpansion<A>& a, const FixedExpansion<B>& b) {
  FixedExpansion<A + B> r;
  r.add(a);
  r.add(b);
  return r;
}
template <int A, int B>
FixedExpansion<A + B> difference(const FixedExpansion<A>& a, const FixedExpansion<B>& b) {
  FixedExpansion<A + B> r;
  r.add(a);
  for (int i = 0; i < b.n; ++i) r.grow(-b.c[i]);
  return r;
}

}  // namespace hprt::exact
