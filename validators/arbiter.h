// The exact arbiter of ray disputes: which triangle does a ray hit first? The
// float ray and float vertices are taken exactly as doubles; the Plücker edge
// functions, the plane determinant and the t numerator are evaluated exactly
// with floating-point expansions (Shewchuk 1997, two-sum/two-product via fma),
// so every sign (inside/outside, on an edge, on a vertex) and every comparison
// of t between candidates or against tnear/tfar is exact.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "bvh/input/prim_info.h"  // PrimRef
#include "core/hit.h"
#include "core/ray.h"
#include "core/scene.h"

namespace hprt {

// One candidate triangle against one ray, exactly.
struct CandidateResult {
  PrimRef prim{kInvalidId, kInvalidId};
  bool valid = false;   // the triangle exists, is finite and has non-zero area (exactly)
  bool inside = false;  // the ray's line crosses the closed triangle, not parallel to its plane
  bool hit = false;     // inside and tnear < t <= tfar (Embree 3's interval), exactly
  double t = 0.0;       // t of the plane crossing, rounded to double (when not parallel)
  int zero_edges = 0;   // edge functions exactly 0 when inside: 1 = on an edge, 2 = on a vertex
  // Signed distance (world units) from the ray's line to the nearest edge line
  // of the triangle: > 0 strictly inside, 0 on an edge, < 0 outside (double).
  double margin = 0.0;
  double scale = 0.0;  // largest |coordinate| of the ray origin and the vertices
  // Change of t per unit offset of the plane along its normal, |n| / |d·n|:
  // large for grazing rays, whose float t is ill-conditioned.
  double t_per_distance = 0.0;
  // The triangle projected along the ray onto a plane perpendicular to it, in
  // world units, with the ray's line at (0, 0) (double: for tolerance checks
  // such as whether the triangles near the line cover all around it).
  double proj[3][2] = {};
  // Set by the ray diff (mark_surrounded): a hit near its border whose
  // neighbours at the same t cover all around the ray's line.
  bool surrounded = false;
};

struct ArbiterAnswer {
  bool hit = false;
  PrimRef prim{kInvalidId,
               kInvalidId};  // closest hit (the first in candidate order among exact ties)
  double t = 0.0;            // its t
  bool tie = false;          // another candidate is hit at exactly the same t
  size_t hits = 0;           // candidates hit
  std::vector<CandidateResult> candidates;  // one per candidate, input order
};

// Rays that hprt defines as misses (the Embree 3 contract, as the embree
// backend and validators/ray_sets kind "nan" define it): a NaN, infinite or
// above-FLT_LARGE (1.844e18) component of origin or direction, a zero
// direction, tnear < 0, tnear > tfar or a NaN interval.
bool arbiter_ray_valid(const Ray& ray);

// Exact test of one ray against one triangle (vertices as given).
CandidateResult arbitrate_triangle(const Ray& ray, const Vec3f& v0, const Vec3f& v1,
                                   const Vec3f& v2);

// The closest exact hit among `candidates` (invalid refs never hit).
ArbiterAnswer arbitrate(const Scene& scene, const Ray& ray, std::span<const PrimRef> candidates);

// Every triangle of the scene whose edge functions, evaluated in double with
// a safe error bound, do not prove that the ray's line passes farther than
// near_rel * scale outside it (scale = largest coordinate of the ray origin
// and the triangle): a superset of the triangles the ray hits, plus, with
// near_rel > 0, the neighbours it just misses. O(triangles) per ray.
std::vector<PrimRef> line_candidates(const Scene& scene, const Ray& ray, double near_rel = 0.0);

// arbitrate() over line_candidates(): the exact answer over the whole scene.
ArbiterAnswer arbitrate_brute_force(const Scene& scene, const Ray& ray, double near_rel = 0.0);

// Exact sign of t(a) - t(b) for two candidates of the same ray that are both
// inside (not parallel): -1, 0 or 1.
int compare_t(const Scene& scene, const Ray& ray, PrimRef a, PrimRef b);

}  // namespace hprt
