// Ray/triangle tests, both double-sided, both reporting Embree's barycentrics
// (u = weight of v1, v = weight of v2) and Embree 3's interval: a hit counts
// when tnear < t <= tfar (Embree 3.13 kernels/geometry/
// triangle_intersector_moeller.h: `(absDen*tnear < T) & (T <= absDen*tfar)`;
// triangle_intersector_woop.h: `(tnear < t) & (t <= tfar)`).
//  - WatertightTest: Woop, Benthin & Wald, "Watertight Ray/Triangle
//    Intersection", JCGT 2(1), 2013: shear/scale into ray space, edge
//    functions U, V, W in double (exact products, see below), hit when
//    all >= 0 or all <= 0 and det != 0. No gaps along shared edges.
//  - MollerTest: Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle
//    Intersection", JGT 1997, with precomputed edges e1, e2 and, as in Embree,
//    the division deferred until the hit is confirmed.
// Each test has a per-ray `Prepared` state built once before traversal.
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>

#include "bvh/layout/leaf_triangles.h"
#include "core/force_inline.h"
#include "core/ray.h"
#include "core/vec.h"

namespace hprt {

// The candidate hit of one test.
struct TriangleHit {
  float t, u, v;
};

namespace detail {
// x with its sign flipped when `sign_of` is negative (the paper's xorf).
inline float xor_sign(float x, float sign_of) { return std::signbit(sign_of) ? -x : x; }
}  // namespace detail

struct WatertightTest {
  struct Prepared {
    Vec3f org;
    int kx = 0, ky = 1, kz = 2;
    float sx = 0, sy = 0, sz = 0;
  };

  // Sec. 3 of the paper: kz = dimension of the largest |dir| component, kx and
  // ky the next two, swapped when dir[kz] < 0 to keep the winding; shear
  // constants Sx, Sy, Sz.
  HPRT_FORCE_INLINE static Prepared prepare(const Ray& r) {
    Prepared p;
    p.org = r.org;
    const Vec3f a(std::fabs(r.dir.x), std::fabs(r.dir.y), std::fabs(r.dir.z));
    p.kz = a.x >= a.y ? (a.x >= a.z ? 0 : 2) : (a.y >= a.z ? 1 : 2);
    p.kx = p.kz == 2 ? 0 : p.kz + 1;
    p.ky = p.kx == 2 ? 0 : p.kx + 1;
    if (r.dir[p.kz] < 0.0f) std::swap(p.kx, p.ky);
    p.sx = r.dir[p.kx] / r.dir[p.kz];
    p.sy = r.dir[p.ky] / r.dir[p.kz];
    p.sz = 1.0f / r.dir[p.kz];
    return p;
  }

  HPRT_FORCE_INLINE static float shear(float x, float s, float z) {
    return float(double(x) - double(s) * double(z));
  }

  HPRT_FORCE_INLINE static bool intersect(const Prepared& p, const Vec3f& v0, const Vec3f& v1,
                                          const Vec3f& v2, float tnear, float tfar,
                                          TriangleHit& hit) {
    const Vec3f a = v0 - p.org, b = v1 - p.org, c = v2 - p.org;
    return intersect_relative(p, {a[p.kx], a[p.ky], a[p.kz]}, {b[p.kx], b[p.ky], b[p.kz]},
                              {c[p.kx], c[p.ky], c[p.kz]}, tnear, tfar, hit);
  }

  // The test from the vertices minus the ray origin, each already on the
  // permuted axes (kx, ky, kz).
  HPRT_FORCE_INLINE static bool intersect_relative(const Prepared& p, const Vec3f& a,
                                                   const Vec3f& b, const Vec3f& c, float tnear,
                                                   float tfar, TriangleHit& hit) {
    // Sheared 2D vertices. Each must come out bit-identical in every triangle
    // that shares the vertex, whatever the compiler does: `x - s*z` in float
    // may or may not be contracted into an FMA depending on the inlining
    // context (seen with g++ 12 -O3 -march=native: 24 leaks in 10k vertex/edge
    // probes). Evaluated in double, s*z is exact, so fused or not the result
    // is the same correctly rounded value, then rounded once to float.
    const float ax = shear(a.x, p.sx, a.z), ay = shear(a.y, p.sy, a.z);
    const float bx = shear(b.x, p.sx, b.z), by = shear(b.y, p.sy, b.z);
    const float cx = shear(c.x, p.sx, c.z), cy = shear(c.y, p.sy, c.z);
    // U, V, W: scaled barycentrics of v0, v1, v2 (edge functions). They are
    // evaluated in double: the products of two floats are exact there, so
    // each edge function is the correctly rounded difference of exact
    // products, which (a) is exactly antisymmetric, so the two triangles of a
    // shared edge see opposite values whatever the compiler contracts into
    // FMAs, and (b) has the true sign -- this subsumes the paper's Sec. 4
    // double fallback for U, V or W == 0. (In float, g++'s default
    // -ffp-contract=fast fuses one product of `cx*by - cy*bx` and breaks
    // watertightness: tests/bvh/test_ray_triangle.cpp FanEdgesAndVertexNeverLeak.)
    const double u = double(cx) * double(by) - double(cy) * double(bx);
    const double v = double(ax) * double(cy) - double(ay) * double(cx);
    const double w = double(bx) * double(ay) - double(by) * double(ax);
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
    const double det = u + v + w;
    if (det == 0.0) return false;
    const double az = double(p.sz) * a.z, bz = double(p.sz) * b.z, cz = double(p.sz) * c.z;
    // Fused explicitly: left to the compiler, whether these products are
    // contracted into FMAs depends on the inlining context, and the packet
    // version (ray_triangle_lanes.h) must give the same bits.
    const double tt = std::fma(w, cz, std::fma(v, bz, u * az));
    const double rcp = 1.0 / det;
    const float t = float(tt * rcp);
    if (!(tnear < t && t <= tfar)) return false;
    hit.t = t;
    hit.u = float(v * rcp);  // weight of v1
    hit.v = float(w * rcp);  // weight of v2
    return true;
  }

  // Requests the cache lines of the leaf's verts block (its rows span it).
  HPRT_FORCE_INLINE static void prefetch(const LeafTriangles& tris, const LeafRange& leaf) {
    const char* b = reinterpret_cast<const char*>(tris.vert_row(leaf.block_first, 0, 0));
    __builtin_prefetch(b);
    __builtin_prefetch(b + 9 * sizeof(float) * leaf.block_count - 1);
  }

  // Triangle i of `leaf`: the nine coordinates the test needs, one from each
  // row of the leaf's verts block.
  HPRT_FORCE_INLINE static bool intersect(const Prepared& p, const LeafTriangles& tris,
                                          const LeafRange& leaf, uint32_t i, float tnear,
                                          float tfar, TriangleHit& hit) {
    const float* q = tris.vert_row(leaf.block_first, leaf.block_count, 0) + (i - leaf.block_first);
    const size_t s = leaf.block_count;
    const auto rel = [&](int k) {
      const float* v = q + 3 * k * s;
      return Vec3f{v[p.kx * s] - p.org[p.kx], v[p.ky * s] - p.org[p.ky], v[p.kz * s] - p.org[p.kz]};
    };
    return intersect_relative(p, rel(0), rel(1), rel(2), tnear, tfar, hit);
  }
};

struct MollerTest {
  struct Prepared {
    Vec3f org, dir;
  };
  HPRT_FORCE_INLINE static Prepared prepare(const Ray& r) { return {r.org, r.dir}; }

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
    const char* b = reinterpret_cast<const char*>(tris.edges.data() + leaf.first);
    __builtin_prefetch(b);
    __builtin_prefetch(b + leaf.count * sizeof(TriangleEdges) - 1);
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
