// The point queries (`inside` and `closest`): their results, shared by every
// backend, the CLI's files and the validators.
//  - inside: where a point lies against the scene's closed meshes, by the
//    parity of the surface crossings of a ray from it in kInsideDirection
//    (every crossing counted exactly once, ray_triangle_exact.h), or on a
//    triangle exactly (exact_predicates.h).
//  - closest: the nearest point of any triangle within a maximum distance,
//    from closest_point_on_triangle in double; among triangles at exactly the
//    same distance the smallest (geomID, primID) wins, so every backend and
//    the brute-force check name the same one.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "core/hit.h"
#include "core/vec.h"

namespace hprt {

// The `inside` answer per point (one byte in the CLI's output file).
enum class PointLocation : uint8_t { kOutside = 0, kInside = 1, kOnSurface = 2 };

// The ray direction of the inside test. Any direction gives the same answer
// (crossings are exact); one off the axes and the diagonals makes the exact
// fallback rare on meshes that are aligned with them.
inline constexpr Vec3f kInsideDirection{0.4821f, 0.6135f, 0.6254f};

// 32 bytes per point, the record of the CLI's `closest` file. A point with
// nothing within the maximum distance (or that is not finite) gets
// distance = +inf, point = (+inf, +inf, +inf), u = v = 0 and invalid IDs.
struct ClosestPoint {
  Vec3f point{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
              std::numeric_limits<float>::infinity()};
  float distance = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;  // barycentric weights of v1 and v2, as a hit's
  uint32_t geom_id = kInvalidId, prim_id = kInvalidId;

  bool found() const { return geom_id != kInvalidId; }
};
static_assert(sizeof(ClosestPoint) == 32, "the closest file's record");

// The closest point of triangle abc to p in double (Ericson, "Real-Time
// Collision Detection", 5.1.5: the Voronoi region of p decides), with its
// squared distance and the weights u (of b) and v (of c).
struct TrianglePoint {
  double x, y, z;
  double d2;
  double u, v;
};
inline TrianglePoint closest_point_on_triangle(const Vec3f& pf, const Vec3f& af, const Vec3f& bf,
                                               const Vec3f& cf) {
  const double p[3] = {pf.x, pf.y, pf.z}, a[3] = {af.x, af.y, af.z}, b[3] = {bf.x, bf.y, bf.z},
               c[3] = {cf.x, cf.y, cf.z};
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int k = 0; k < 3; ++k) {
    ab[k] = b[k] - a[k];
    ac[k] = c[k] - a[k];
    ap[k] = p[k] - a[k];
    bp[k] = p[k] - b[k];
    cp[k] = p[k] - c[k];
  }
  // Every product and fma is spelled out, so no compiler contraction can
  // make two call sites (the bvh, Embree's callback, the brute force) differ.
  const auto dot = [](const double* x, const double* y) {
    return std::fma(x[0], y[0], std::fma(x[1], y[1], x[2] * y[2]));
  };
  // Weights of b and c.
  double wb = 0.0, wc = 0.0;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  const double vc = std::fma(d1, d4, -(d3 * d2));
  const double vb = std::fma(d5, d2, -(d1 * d6));
  const double va = std::fma(d3, d6, -(d5 * d4));
  if (d1 <= 0.0 && d2 <= 0.0) {
    // vertex a
  } else if (d3 >= 0.0 && d4 <= d3) {
    wb = 1.0;
  } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    wb = d1 / (d1 - d3);
  } else if (d6 >= 0.0 && d5 <= d6) {
    wc = 1.0;
  } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    wc = d2 / (d2 - d6);
  } else if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    wc = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    wb = 1.0 - wc;
  } else {
    const double denom = 1.0 / (va + vb + vc);
    wb = vb * denom;
    wc = vc * denom;
  }
  TrianglePoint r;
  double q[3];
  // Vertices exactly where the region is a vertex (a + 1 * (b - a) may round).
  for (int k = 0; k < 3; ++k)
    q[k] = wb == 1.0 ? b[k] : (wc == 1.0 ? c[k] : std::fma(wb, ab[k], std::fma(wc, ac[k], a[k])));
  r.x = q[0];
  r.y = q[1];
  r.z = q[2];
  const double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
  r.d2 = std::fma(dx, dx, std::fma(dy, dy, dz * dz));
  r.u = wb;
  r.v = wc;
  return r;
}

// Whether a candidate at squared distance d2 with IDs (g, p) beats the best
// so far (best_d2, best_g, best_p): nearer, or as near with smaller IDs.
inline bool closest_before(double d2, uint32_t g, uint32_t p, double best_d2, uint32_t best_g,
                           uint32_t best_p) {
  if (d2 != best_d2) return d2 < best_d2;
  return g != best_g ? g < best_g : p < best_p;
}

// The closest query's reach: a point is found when its reported (float)
// distance is <= max_distance. The search runs with a slightly larger
// radius (squared here), so that a triangle whose float distance rounds down
// to max_distance is still seen; keep_within then drops what lies beyond.
inline double closest_search_d2(float max_distance) {
  const double r = double(max_distance) * (1.0 + 0x1p-20);
  return r * r;
}
inline ClosestPoint keep_within(const ClosestPoint& c, float max_distance) {
  return c.distance <= max_distance ? c : ClosestPoint{};
}

// The record of a candidate.
inline ClosestPoint to_closest_point(const TrianglePoint& t, uint32_t geom_id, uint32_t prim_id) {
  ClosestPoint c;
  c.point = Vec3f{float(t.x), float(t.y), float(t.z)};
  c.distance = float(std::sqrt(t.d2));
  c.u = float(t.u);
  c.v = float(t.v);
  c.geom_id = geom_id;
  c.prim_id = prim_id;
  return c;
}

}  // namespace hprt
