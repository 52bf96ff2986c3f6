// The exact decision of the watertight ray/triangle test, for the rare tests
// whose double edge functions the error bound cannot decide.
//
// Notation: on the permuted axes (kx, ky, kz) of WatertightRay, o and d are
// the float ray, A = vertex - o, s_x = d_x/d_z, and the sheared coordinates
// are X = A_x - s_x A_z, Y = A_y - s_y A_z. The edge function of the edge
// (p, q) is E = X_q Y_p - Y_q X_p (U: (v1, v2), V: (v2, v0), W: (v0, v1)),
// and d_z * E = T = d . ((q - o) x (p - o)), a degree-3 polynomial in the
// float inputs.
//
// The bound of the double path (ray_triangle.h): A and x - s*z are one
// double rounding each (relative eps = 2^-53), s_x = d_x * (1/d_z) two, so
// |x - X| <= 4.01 eps m_x with m_x = |A_x| + |s_x||A_z| <= (|x| + 2|A_z|)
// (1 + 4.01 eps), since |s_x| <= 1 (d_z is the largest component). The edge
// function, one product and one fma, then satisfies |E_computed - E| <=
// 6.05 eps (n_q a_p + n_p a_q) + 32.3 eps^2 n_p n_q with a = |x| + |y|,
// n = a + 2|z|; the code's 8 eps n (a + 8 eps |z|) covers it with room for
// the bound's own rounding, plus 2^-900 for products that underflow. The
// lane tests use one bound per ray instead: with M = 2 max |corner - o| over
// the root box's corners and axes, m <= M for every vertex in the box, and
// since |x|, |y| <= (1 + e) M the error is below 24.2 eps M^2; 2^-47 M^2
// (64 eps M^2) covers it. It is looser (a ray within ~1e-13 of the scale of
// an edge goes to the scalar test) but costs one comparison per edge
// function.
//
// Exactly: T is evaluated as a floating-point expansion. Where T = 0 the ray
// passes exactly through the edge's line; the tie is broken as if the ray
// were moved by (e, e^2) in the sheared plane, e -> 0+ (one fixed
// perturbation per ray, a top-left rule): the sign becomes that of Y_q - Y_p,
// or of X_p - X_q where that is 0 too. A perturbed ray is a generic ray, so
// of the triangles around a shared edge or vertex exactly as many are hit as
// a ray just beside it would hit: one where the surface is crossed, none or
// two where it only touches (a silhouette), never a gap. The triangle is hit
// when the three perturbed signs agree (then the determinant is non-zero).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/force_inline.h"
#include "core/vec.h"

namespace hprt {

// The candidate hit of one test.
struct TriangleHit {
  float t, u, v;
};

// The watertight test's per-ray state (WatertightTest::prepare).
struct WatertightRay {
  Vec3f org, dir;                 // the ray as given
  int kx = 0, ky = 1, kz = 2;     // permuted axes
  double ox = 0, oy = 0, oz = 0;  // org on them
  double sx = 0, sy = 0, sz = 0;  // shear: d_x/d_z, d_y/d_z, 1/d_z
  // The lane tests' error bound of any edge function of a triangle within
  // the traversal's root box (WatertightTest::prepare with the box); +inf
  // when no box was given, which sends every lane to the scalar test.
  double lane_bound = HUGE_VAL;
};

// The double path's edge functions e = (U, V, W), their error bounds
// (|e - exact| <= bound) and the vertices' z relative to the origin
// (WatertightTest::edge_functions).
struct EdgeFunctions {
  double e[3], bound[3], z[3];
};

// t, u, v from the double edge functions (det = U + V + W != 0); false when
// t is outside (tnear, tfar]. The one formula of every path: the lanes
// compute the same operations.
HPRT_FORCE_INLINE bool edge_function_hit(const EdgeFunctions& f, double sz, float tnear, float tfar,
                                         TriangleHit& hit) {
  const double u = f.e[0], v = f.e[1], w = f.e[2];
  const double det = u + v + w;
  // Fused explicitly: the lanes must give the same bits.
  const double tt = std::fma(w, sz * f.z[2], std::fma(v, sz * f.z[1], u * (sz * f.z[0])));
  const double rcp = 1.0 / det;
  const float t = float(tt * rcp);
  if (!(tnear < t && t <= tfar)) return false;
  hit.t = t;
  hit.u = float(v * rcp);  // weight of v1
  hit.v = float(w * rcp);  // weight of v2
  return true;
}

// The test decided exactly: vertices on the permuted axes (kx, ky, kz), `f`
// the double path's values for them. A hit at tnear < t <= tfar fills `hit`:
// t, u, v from `f` when its signs agree with the exact ones (so the answer
// does not depend on which error bound sent the test here: the lanes may use
// a looser one than the scalar test), else from the exact values, rounded.
// Never inlined: it is the rare path.
[[gnu::noinline]] bool watertight_exact(const WatertightRay& ray, const float (&v)[3][3],
                                        const EdgeFunctions& f, float tnear, float tfar,
                                        TriangleHit& hit);

// How many tests went to watertight_exact since the process started (all
// threads; for `hprt bench trace`'s report of how rare it is).
uint64_t exact_fallback_count();

}  // namespace hprt
