// Exact geometric predicates on float points (the point queries' decisions):
// the sign of a plane side, of a plane against a direction, and whether a
// point lies on a closed triangle. Each is a double evaluation with an error
// bound (Shewchuk's orient3d bound), redone exactly where the bound cannot
// decide. The exact path uses that a product of two floats is exact in
// double (24 + 24 bits), so a product of three is a two-term expansion
// (two_product) and a 3x3 determinant of float rows is a sum of six of them.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/exact_arith.h"
#include "core/vec.h"

namespace hprt::exact {

namespace detail {
// Shewchuk's o3derrboundA, (7 + 56 eps) eps with eps = 2^-53: bounds the
// error of the double evaluation below (differences rounded, then products
// and sums) relative to its permanent.
inline constexpr double kOrient3dBound = (7.0 + 56.0 * 0x1p-53) * 0x1p-53;

// e += sign * x * y * z exactly (x * y is exact in double).
template <int N>
void add_triple(FixedExpansion<N>& e, double sign, float x, float y, float z) {
  double hi, lo;
  two_product(double(x) * double(y), double(z), hi, lo);
  e.grow(sign * lo);
  e.grow(sign * hi);
}

// e += sign * det[X; Y; Z] (rows) = sign * X . (Y x Z): six triple products.
template <int N>
void add_det3(FixedExpansion<N>& e, double sign, const Vec3f& X, const Vec3f& Y, const Vec3f& Z) {
  add_triple(e, sign, X.x, Y.y, Z.z);
  add_triple(e, -sign, X.x, Y.z, Z.y);
  add_triple(e, -sign, X.y, Y.x, Z.z);
  add_triple(e, sign, X.y, Y.z, Z.x);
  add_triple(e, sign, X.z, Y.x, Z.y);
  add_triple(e, -sign, X.z, Y.y, Z.x);
}

// det[r0; r1; r2] of double rows with its permanent (for the error bound).
inline double det3(const double (&r0)[3], const double (&r1)[3], const double (&r2)[3],
                   double& permanent) {
  const double m0 = r1[1] * r2[2] - r1[2] * r2[1];
  const double m1 = r1[2] * r2[0] - r1[0] * r2[2];
  const double m2 = r1[0] * r2[1] - r1[1] * r2[0];
  permanent = (std::fabs(r1[1] * r2[2]) + std::fabs(r1[2] * r2[1])) * std::fabs(r0[0]) +
              (std::fabs(r1[2] * r2[0]) + std::fabs(r1[0] * r2[2])) * std::fabs(r0[1]) +
              (std::fabs(r1[0] * r2[1]) + std::fabs(r1[1] * r2[0])) * std::fabs(r0[2]);
  return r0[0] * m0 + r0[1] * m1 + r0[2] * m2;
}

inline int sign_of(double x) { return (x > 0.0) - (x < 0.0); }

// The double filter of det[b - a; c - a; r2]: true with its sign in `sign`
// when the error bound decides it.
inline bool filtered_det(const Vec3f& a, const Vec3f& b, const Vec3f& c, const double (&r2)[3],
                         int& sign) {
  const double r0[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
  const double r1[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
  double permanent;
  const double det = det3(r0, r1, r2, permanent);
  sign = sign_of(det);
  return std::fabs(det) > kOrient3dBound * permanent;
}
}  // namespace detail

// Sign of ((b - a) x (c - a)) . (p - a): > 0 when p lies on the side the
// normal of the counter-clockwise triangle abc points to, 0 on its plane.
inline int orient3d(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& p) {
  const double r2[3] = {double(p.x) - a.x, double(p.y) - a.y, double(p.z) - a.z};
  int sign;
  if (detail::filtered_det(a, b, c, r2, sign)) return sign;
  // det[B - A; C - A; P - A] = det[B; C; P] - det[A; C; P] - det[B; A; P] - det[B; C; A]
  // (rows are linear; any term with A twice vanishes).
  FixedExpansion<48> e;
  detail::add_det3(e, 1.0, b, c, p);
  detail::add_det3(e, -1.0, a, c, p);
  detail::add_det3(e, -1.0, b, a, p);
  detail::add_det3(e, -1.0, b, c, a);
  return e.sign();
}

// Sign of ((b - a) x (c - a)) . d: whether a ray of direction d meets the
// plane of abc from its back (> 0) or front (< 0) side, 0 when parallel.
inline int plane_direction(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& d) {
  const double r2[3] = {d.x, d.y, d.z};
  int sign;
  if (detail::filtered_det(a, b, c, r2, sign)) return sign;
  FixedExpansion<36> e;
  detail::add_det3(e, 1.0, b, c, d);
  detail::add_det3(e, -1.0, a, c, d);
  detail::add_det3(e, -1.0, b, a, d);
  return e.sign();
}

// (b - a) x (c - a) on the axes (i, j), exactly: six products of floats,
// each exact in double, summed as an expansion.
inline FixedExpansion<6> orient2d(const Vec3f& a, const Vec3f& b, const Vec3f& c, int i, int j) {
  FixedExpansion<6> e;
  const double terms[6] = {double(b[i]) * c[j],  -double(b[i]) * a[j], -double(a[i]) * c[j],
                           -double(b[j]) * c[i], double(b[j]) * a[i],  double(a[j]) * c[i]};
  for (double t : terms) e.grow(t);
  return e;
}

// Whether p lies on the closed triangle abc (its interior, edges or
// vertices), exactly. A triangle of zero area (exactly) has no surface.
inline bool on_triangle(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& p) {
  for (int k = 0; k < 3; ++k)
    if (p[k] < std::min({a[k], b[k], c[k]}) || p[k] > std::max({a[k], b[k], c[k]})) return false;
  if (orient3d(a, b, c, p) != 0) return false;
  // Coplanar: the projection that keeps the most area decides.
  int best = -1;
  double best_area = 0.0;
  int area_sign = 0;
  for (int k = 0; k < 3; ++k) {
    const FixedExpansion<6> area = orient2d(a, b, c, (k + 1) % 3, (k + 2) % 3);
    if (area.sign() != 0 && std::fabs(area.estimate()) > best_area) {
      best = k;
      best_area = std::fabs(area.estimate());
      area_sign = area.sign();
    }
  }
  if (best < 0) return false;
  const int i = (best + 1) % 3, j = (best + 2) % 3;
  return orient2d(a, b, p, i, j).sign() * area_sign >= 0 &&
         orient2d(b, c, p, i, j).sign() * area_sign >= 0 &&
         orient2d(c, a, p, i, j).sign() * area_sign >= 0;
}

}  // namespace hprt::exact
