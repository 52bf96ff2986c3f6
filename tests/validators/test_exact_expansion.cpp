// Expansion arithmetic checked against values it must represent exactly:
// integers and dyadic rationals whose sums and products need more than one
// double, compared through 128-bit integers or through exact cancellation.
#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/exact_arith.h"
#include "core/splitmix64.h"
#include "validators/exact_expansion.h"

namespace hprt::exact {
namespace {

__extension__ typedef __int128 Int128;  // GCC's 128-bit integers: exact products of 50-bit ints

// The exact value of an expansion whose components are integers below 2^126.
Int128 as_int128(const Expansion& e) {
  Int128 v = 0;
  for (double c : e.components()) {
    EXPECT_EQ(c, std::trunc(c)) << "component is not an integer";
    v += static_cast<Int128>(c);
  }
  return v;
}

void expect_nonoverlapping_increasing(const Expansion& e) {
  const auto& c = e.components();
  for (size_t i = 0; i < c.size(); ++i) {
    EXPECT_NE(c[i], 0.0) << "zero component " << i;
    if (i == 0) continue;
    EXPECT_LT(std::fabs(c[i - 1]), std::fabs(c[i])) << "components out of order at " << i;
    // Non-overlapping: the smaller one lies below the larger one's lowest set bit.
    int exponent = 0;
    const uint64_t mantissa = uint64_t(std::ldexp(std::fabs(std::frexp(c[i], &exponent)), 53));
    const double lowest_bit = std::ldexp(1.0, exponent - 53 + std::countr_zero(mantissa));
    EXPECT_LT(std::fabs(c[i - 1]), lowest_bit) << "components overlap at " << i;
  }
}

TEST(ExactExpansion, ZeroHasNoComponentsAndSignZero) {
  EXPECT_EQ(Expansion().sign(), 0);
  EXPECT_EQ(Expansion(0.0).sign(), 0);
  EXPECT_TRUE(Expansion(0.0).components().empty());
  EXPECT_EQ((Expansion(3.5) - Expansion(3.5)).sign(), 0);
  EXPECT_TRUE((Expansion(3.5) - Expansion(3.5)).components().empty());
}

TEST(ExactExpansion, SumKeepsWhatOneDoubleRoundsAway) {
  // 1 + 2^-80 - 1 is 2^-80 exactly; in doubles it is 0.
  const double tiny = std::ldexp(1.0, -80);
  const Expansion e = Expansion(1.0) + Expansion(tiny) - Expansion(1.0);
  EXPECT_EQ(e.sign(), 1);
  EXPECT_EQ(e.estimate(), tiny);
  const Expansion neg = Expansion(1.0) - Expansion(tiny) - Expansion(1.0);
  EXPECT_EQ(neg.sign(), -1);
  EXPECT_EQ(neg.estimate(), -tiny);
}

TEST(ExactExpansion, ProductsEqualInt128Arithmetic) {
  SplitMix64 rng(7);
  for (int i = 0; i < 2000; ++i) {
    // Integers of up to 50 bits: their products need up to 100 bits.
    const int64_t a = int64_t(rng.next() >> 14) - (int64_t(1) << 49);
    const int64_t b = int64_t(rng.next() >> 14) - (int64_t(1) << 49);
    const int64_t c = int64_t(rng.next() >> 14) - (int64_t(1) << 49);
    const int64_t d = int64_t(rng.next() >> 14) - (int64_t(1) << 49);
    const Expansion det =
        Expansion(double(a)) * Expansion(double(d)) - Expansion(double(b)) * Expansion(double(c));
    const Int128 want = Int128(a) * d - Int128(b) * c;
    EXPECT_TRUE(as_int128(det) == want) << a << " " << b << " " << c << " " << d;
    EXPECT_EQ(det.sign(), want > 0 ? 1 : (want < 0 ? -1 : 0));
    expect_nonoverlapping_increasing(det);
  }
}

TEST(ExactExpansion, SignOfNearlySingularDeterminantIsExact) {
  // det [[x, y], [x + u, y + u']] with u, u' one ulp apart: doubles give 0 or
  // the wrong sign, the expansion gives the exact sign.
  const double x = 1.0 + std::ldexp(1.0, -30);
  const double y = 1.0 - std::ldexp(1.0, -29);
  const double x2 = std::nextafter(x, 2.0);
  const double y2 = y;
  // x * y2 - y * x2 = y (x - x2) < 0 exactly.
  const Expansion det = Expansion(x) * Expansion(y2) - Expansion(y) * Expansion(x2);
  EXPECT_EQ(det.sign(), -1);
  const Expansion swapped = Expansion(y) * Expansion(x2) - Expansion(x) * Expansion(y2);
  EXPECT_EQ(swapped.sign(), 1);
  EXPECT_EQ((det + swapped).sign(), 0);
}

TEST(ExactExpansion, DiffIsExactForFloatsOfAnyScale) {
  const float values[] = {0.0f,  1.0f,     -1.0f,   1e-30f,  -3e-20f,
                          1e30f, -7.5e25f, FLT_MIN, FLT_MAX, std::nextafter(1.0f, 2.0f)};
  for (float a : values) {
    for (float b : values) {
      const Expansion d = diff(a, b);
      // d + b - a must vanish exactly.
      EXPECT_EQ((d + Expansion(double(b)) - Expansion(double(a))).sign(), 0) << a << " " << b;
      EXPECT_EQ(d.sign(), a > b ? 1 : (a < b ? -1 : 0)) << a << " " << b;
    }
  }
}

TEST(ExactExpansion, NegationAndEstimate) {
  const Expansion e = Expansion(std::ldexp(1.0, 60)) + Expansion(3.0);
  EXPECT_EQ((-e).sign(), -1);
  EXPECT_EQ((-e).estimate(), -e.estimate());
  EXPECT_EQ(e.components().size(), 2u);
  EXPECT_TRUE(as_int128(e) == (Int128(1) << 60) + 3);
}

// The fixed-size expansions of the triangle test's exact path
// (core/exact_arith.h) against the arbiter's growing ones: the same triple
// products d . ((q - o) x (p - o)) of random floats, including ones that
// cancel exactly, must have the same sign and the same estimate.
TEST(FixedExpansion, TripleProductsMatchTheArbitersExpansions) {
  SplitMix64 rng(42);
  auto f = [&](int scale) {
    const double u = double(rng.next() >> 11) * 0x1p-53 - 0.5;
    return float(std::ldexp(u, int(rng.next() % 40) - 20) * double(scale));
  };
  int zeros = 0;
  for (int i = 0; i < 20000; ++i) {
    float o[3], d[3], p[3], q[3];
    for (int a = 0; a < 3; ++a) {
      o[a] = f(1);
      d[a] = f(1);
      p[a] = f(1);
      q[a] = f(1);
    }
    if (i % 4 == 0)  // q on the line through p along d, when exact: T = 0
      for (int a = 0; a < 3; ++a) q[a] = p[a] + 2.0f * d[a];
    if (i % 4 == 1)  // p at the origin: T = 0
      for (int a = 0; a < 3; ++a) p[a] = o[a];
    FixedExpansion<2> qe[3], pe[3];
    Expansion qd[3], pd[3];
    for (int a = 0; a < 3; ++a) {
      qe[a] = subtract(q[a], o[a]);
      pe[a] = subtract(p[a], o[a]);
      qd[a] = diff(q[a], o[a]);
      pd[a] = diff(p[a], o[a]);
    }
    FixedExpansion<96> t;
    t.add(scale(difference(product(qe[1], pe[2]), product(qe[2], pe[1])), d[0]));
    t.add(scale(difference(product(qe[2], pe[0]), product(qe[0], pe[2])), d[1]));
    t.add(scale(difference(product(qe[0], pe[1]), product(qe[1], pe[0])), d[2]));
    const Expansion td = Expansion(d[0]) * (qd[1] * pd[2] - qd[2] * pd[1]) +
                         Expansion(d[1]) * (qd[2] * pd[0] - qd[0] * pd[2]) +
                         Expansion(d[2]) * (qd[0] * pd[1] - qd[1] * pd[0]);
    ASSERT_EQ(t.sign(), td.sign()) << i;
    EXPECT_EQ(t.estimate(), td.estimate()) << i;
    zeros += t.sign() == 0;
  }
  EXPECT_GE(zeros, 5000);  // the exact cancellations were exercised
}

TEST(FixedExpansion, SubtractIsExactAcrossExponents) {
  for (double a : {1e30, 1.0, -3e-30, 0x1p100})
    for (double b : {1e-30, 1.0, 7e25, -0x1p-100}) {
      const FixedExpansion<2> e = subtract(float(a), float(b));
      const Expansion ref = diff(float(a), float(b));
      EXPECT_EQ(e.sign(), ref.sign());
      EXPECT_EQ(e.estimate(), ref.estimate());
      ASSERT_EQ(size_t(e.n), ref.components().size());
      for (int k = 0; k < e.n; ++k) EXPECT_EQ(e.c[k], ref.components()[size_t(k)]);
    }
}

}  // namespace
}  // namespace hprt::exact
