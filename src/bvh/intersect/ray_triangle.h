// Ray/triangle tests, both double-sided, both reporting Embree's barycentrics
// (u = weight of v1, v = weight of v2) and Embree 3's interval: a hit counts
// when tnear < t <= tfar (Embree 3.13 kernels/geometry/
// triangle_intersector_moeller.h: `(absDen*tnear < T) & (T <= absDen*tfar)`;
// triangle_intersector_woop.h: `(tnear < t) & (t <= tfar)`).
//  - WatertightTest: Woop, Benthin & Wald, "Watertight Ray/Triangle
//    Intersection", JCGT 2(1), 2013: shear/scale into ray space and edge
//    functions U, V, W, hit when all have one sign. Here every sign is
//    decided exactly for the float ray and float vertices: the edge
//    functions are evaluated in double with a proven error bound, and where
//    the bound cannot decide a sign (the ray passes within about 1e-15 of
//    the scale of an edge, or exactly through it) the test is redone in
//    exact arithmetic (ray_triangle_exact.h). A ray exactly through a shared
//    edge or vertex hits exactly one of the triangles there (a fill rule), so
//    closest hit, any hit and crossing counts never double-count or leak.
//  - MollerTest: Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle
//    Intersection", JGT 1997, with precomputed edges e1, e2 and, as in Embree,
//    the division deferred until the hit is confirmed.
// Each test has a per-ray `Prepared` state built once before traversal.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "bvh/intersect/ray_triangle_exact.h"
#include "bvh/layout/leaf_triangles.h"
#include "core/aabb.h"
#include "core/force_inline.h"
#include "core/prefetch.h"
#include "core/ray.h"
#include "core/vec.h"

namespace hprt {

namespace detail {
// x with its sign flipped when `sign_of` is negative (the paper's xorf).
inline float xor_sign(float x, float sign_of) { return std::signbit(sign_of) ? -x : x; }

// The error bound of the double edge functions (ray_triangle_exact.h derives
// it): |U - exact U| <= n_c * a_b + n_b * a_c + kEdgeErrorAbs for the edge
// (b, c), with, per vertex k, a = |x_k| + |y_k| (sheared), z = |z_k|,
// n_k = kEdgeError * (a + 2z) and a_k = a + kEdgeErrorZ * z.
inline constexpr double kEdgeError = 0x1p-50;      // 8 * 2^-53
inline constexpr double kEdgeErrorZ = 0x1p-50;     // 8 * 2^-53
inline constexpr double kEdgeErrorAbs = 0x1p-900;  // products that underflow
HPRT_FORCE_INLINE double edge_bound(const double (&n)[3], const double (&a)[3], int b, int c) {
  return std::fma(n[c], a[b], std::fma(n[b], a[c], kEdgeErrorAbs));
}
}  // namespace detail

struct WatertightTest {
  using Prepared = WatertightRay;

  // Sec. 3 of the paper: kz = dimension of the largest |dir| component, kx and
  // ky the next two, swapped when dir[kz] < 0 to keep the winding; shear
  // constants Sx, Sy, Sz (in double: their rounding bounds the error below).
  // The lanes' error bound (ray_triangle_exact.h) for rays with origins in
  // [org_lo, org_hi] and triangles inside `root` (the traversal's root box):
  // 2^-47 M^2, M = twice the largest coordinate distance between the two
  // boxes. In float: a rounding of M by 2^-24 is far inside the bound's
  // margin, and an overflow gives +inf (every lane to the scalar test).
  HPRT_FORCE_INLINE static double lane_bound(const Vec3f& org_lo, const Vec3f& org_hi,
                                             const AABB& root) {
    if (root.empty()) return HUGE_VAL;
#if defined(__SSE2__)
    // The same maximum on the three axes at once (the fourth lane is 0): it
    // is computed for every ray, and a scalar chain of twelve maxima costs
    // about a tenth of a short ray's time.
    const auto v = [](const Vec3f& a) { return _mm_setr_ps(a.x, a.y, a.z, 0.0f); };
    const __m128 lo = v(org_lo), hi = v(org_hi), mn = v(root.min), mx = v(root.max);
    const __m128 sign = _mm_set1_ps(-0.0f);
    const auto dist = [&](__m128 a, __m128 b) { return _mm_andnot_ps(sign, _mm_sub_ps(a, b)); };
    __m128 d =
        _mm_max_ps(_mm_max_ps(dist(mx, lo), dist(mn, hi)), _mm_max_ps(dist(mx, hi), dist(mn, lo)));
    d = _mm_max_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(2, 3, 0, 1)));
    d = _mm_max_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(1, 0, 3, 2)));
    const float m = _mm_cvtss_f32(d);
#else
    float m = 0.0f;
    for (int a = 0; a < 3; ++a)
      m = std::max({m, std::fabs(root.max[a] - org_lo[a]), std::fabs(root.min[a] - org_hi[a]),
                    std::fabs(root.max[a] - org_hi[a]), std::fabs(root.min[a] - org_lo[a])});
#endif
    const double m2 = 2.0 * double(m);
    return std::fma(0x1p-47 * m2, m2, detail::kEdgeErrorAbs);
  }

  // The same with the lanes' error bound for triangles inside `root`.
  HPRT_FORCE_INLINE static Prepared prepare(const Ray& r, const AABB& root) {
    Prepared p = prepare(r);
    p.lane_bound = lane_bound(r.org, r.org, root);
    return p;
  }

  // Written without branches on the direction (selects and table lookups):
  // for incoherent rays the axis choice is a coin toss that a branch
  // predictor loses.
  HPRT_FORCE_INLINE static Prepared prepare(const Ray& r) {
    static constexpr int kNext[3] = {1, 2, 0};
    Prepared p;
    p.org = r.org;
    p.dir = r.dir;
    const float o[3] = {r.org.x, r.org.y, r.org.z}, d[3] = {r.dir.x, r.dir.y, r.dir.z};
    const float ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
    // kz: x if |x| >= |y|, |z|; else y if |y| >= |z|; else z.
    const bool x_over_y = ax >= ay;
    const float a_xy = x_over_y ? ax : ay;
    const int k_xy = x_over_y ? 0 : 1;
    p.kz = 2 - int(a_xy >= az) * (2 - k_xy);  // arithmetic, so no branch is emitted
    const int kx = kNext[p.kz], ky = kNext[kx];
    const bool flip = d[p.kz] < 0.0f;  // swapped to keep the winding
    p.kx = flip ? ky : kx;
    p.ky = flip ? kx : ky;
    p.ox = o[p.kx];
    p.oy = o[p.ky];
    p.oz = o[p.kz];
    // One division (s_x, s_y are then rounded twice: 2 eps, which the
    // error bound allows for).
    p.sz = 1.0 / double(d[p.kz]);
    p.sx = double(d[p.kx]) * p.sz;
    p.sy = double(d[p.ky]) * p.sz;
    return p;
  }

  HPRT_FORCE_INLINE static bool intersect(const Prepared& p, const Vec3f& v0, const Vec3f& v1,
                                          const Vec3f& v2, float tnear, float tfar,
                                          TriangleHit& hit) {
    const float v[3][3] = {{v0[p.kx], v0[p.ky], v0[p.kz]},
                           {v1[p.kx], v1[p.ky], v1[p.kz]},
                           {v2[p.kx], v2[p.ky], v2[p.kz]}};
    return intersect_permuted(p, v, tnear, tfar, hit);
  }

  // The double path's edge functions of the vertices on the permuted axes,
  // with their error bounds (derived in ray_triangle_exact.h).
  HPRT_FORCE_INLINE static EdgeFunctions edge_functions(const Prepared& p, const float (&v)[3][3]) {
    // Vertices minus the origin (one rounding), sheared: x - s*z fused.
    EdgeFunctions f;
    double x[3], y[3], bound_n[3], bound_a[3];
    for (int k = 0; k < 3; ++k) {
      const double dx = double(v[k][0]) - p.ox, dy = double(v[k][1]) - p.oy;
      f.z[k] = double(v[k][2]) - p.oz;
      x[k] = std::fma(-p.sx, f.z[k], dx);
      y[k] = std::fma(-p.sy, f.z[k], dy);
      const double a = std::fabs(x[k]) + std::fabs(y[k]), az = std::fabs(f.z[k]);
      bound_n[k] = detail::kEdgeError * std::fma(2.0, az, a);
      bound_a[k] = std::fma(detail::kEdgeErrorZ, az, a);
    }
    // U, V, W: scaled barycentrics of v0, v1, v2 (edge functions).
    f.e[0] = std::fma(x[2], y[1], -(y[2] * x[1]));
    f.e[1] = std::fma(x[0], y[2], -(y[0] * x[2]));
    f.e[2] = std::fma(x[1], y[0], -(y[1] * x[0]));
    f.bound[0] = detail::edge_bound(bound_n, bound_a, 1, 2);
    f.bound[1] = detail::edge_bound(bound_n, bound_a, 2, 0);
    f.bound[2] = detail::edge_bound(bound_n, bound_a, 0, 1);
    return f;
  }

  // The test from the vertices on the permuted axes (kx, ky, kz). Every
  // operation is spelled out (explicit fma, no product left for the compiler
  // to contract) because the lane versions (ray_triangle_lanes.h) must give
  // the same bits, and the same choice of which tests go to the exact path.
  HPRT_FORCE_INLINE static bool intersect_permuted(const Prepared& p, const float (&v)[3][3],
                                                   float tnear, float tfar, TriangleHit& hit) {
    const EdgeFunctions f = edge_functions(p, v);
    const double u = f.e[0], v_ = f.e[1], w = f.e[2];
    if (!(std::fabs(u) > f.bound[0] && std::fabs(v_) > f.bound[1] && std::fabs(w) > f.bound[2]))
      return watertight_exact(p, v, f, tnear, tfar, hit);
    if ((u < 0.0) != (v_ < 0.0) || (u < 0.0) != (w < 0.0)) return false;
    return edge_function_hit(f, p.sz, tnear, tfar, hit);
  }

  // Requests the cache lines of the leaf's verts block (its rows span it).
  HPRT_FORCE_INLINE static void prefetch(const LeafTriangles& tris, const LeafRange& leaf) {
    prefetch_lines(tris.vert_row(leaf.block_first, 0, 0), 9 * sizeof(float) * leaf.block_count);
  }

  // Triangle i of `leaf`: the nine coordinates the test needs, one from each
  // row of the leaf's verts block.
  HPRT_FORCE_INLINE static bool intersect(const Prepared& p, const LeafTriangles& tris,
                                          const LeafRange& leaf, uint32_t i, float tnear,
                                          float tfar, TriangleHit& hit) {
    const float* q = tris.vert_row(leaf.block_first, leaf.block_count, 0) + (i - leaf.block_first);
    const size_t s = leaf.block_count;
    const int axis[3] = {p.kx, p.ky, p.kz};
    float v[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) v[k][a] = q[(3 * k + axis[a]) * s];
    return intersect_permuted(p, v, tnear, tfar, hit);
  }
};

struct MollerTest {
  struct Prepared {
    Vec3f org, dir;
  };
  HPRT_FORCE_INLINE static Prepared prepare(const Ray& r) { return {r.org, r.dir}; }
  HPRT_FORCE_INLINE static Prepared prepare(const Ray& r, const AABB&) { return prepare(r); }

  HPRT_FORCE_INLINE static bool intersect(const Prepared& p, const Vec3f& v0, const Vec3f& e1,
                                          const Vec3f& e2, float tnear, float tfar,
                                          TriangleHit& hit) {
    const Vec3f pv = cross(p.dir, e2);
    const float det = dot(e1, pv);
    if (det == 0.0f) return false;
    const float abs_det = std::fabs(det);
    const Vec3f tv = p.org - v0;
    const float u = detail::xor_sign(dot(tv, pv), det);
    if (!(u >= 0.0f)) return false;
    const Vec3f qv = cross(tv, e1);
    const float v = detail::xor_sign(dot(p.dir, qv), det);
    if (!(v >= 0.0f) || !(u + v <= abs_det)) return false;
    const float tt = detail::xor_sign(dot(e2, qv), det);
    if (!(abs_det * tnear < tt && tt <= abs_det * tfar)) return false;
    const float rcp = 1.0f / abs_det;
    hit.t = tt * rcp;
    hit.u = u * rcp;
    hit.v = v * rcp;
    return true;
  }

  HPRT_FORCE_INLINE static void prefetch(const LeafTriangles& tris, const LeafRange& leaf) {
    prefetch_lines(tris.edges.data() + leaf.first, leaf.count * sizeof(TriangleEdges));
  }

  // Triangle i (of any leaf: the edges are stored triangle by triangle).
  HPRT_FORCE_INLINE static bool intersect(const Prepared& p, const LeafTriangles& tris,
                                          const LeafRange&, uint32_t i, float tnear, float tfar,
                                          TriangleHit& hit) {
    const TriangleEdges& t = tris.edges[i];
    return intersect(p, t.v0, t.e1, t.e2, tnear, tfar, hit);
  }

  // Convenience for tests: the same test from raw vertices.
  static bool intersect_vertices(const Prepared& p, const Vec3f& v0, const Vec3f& v1,
                                 const Vec3f& v2, float tnear, float tfar, TriangleHit& hit) {
    return intersect(p, v0, v1 - v0, v2 - v0, tnear, tfar, hit);
  }
};

}  // namespace hprt
