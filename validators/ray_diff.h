// The ray diff: the same rays through two backends (the one under test,
// called bvh here, and the reference, called embree, whichever they are), each ray
// classified as agree, tie (different primitive at the same t, confirmed by
// the arbiter) or mismatch, and every mismatch settled by the exact arbiter
// (validators/arbiter.h) as bvh right, embree right, both right or both wrong.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "backends/intersector.h"
#include "core/hit.h"
#include "core/ray.h"
#include "core/scene.h"
#include "validators/arbiter.h"

namespace hprt {

struct RayDiffOptions {
  double t_rel_tol = 1e-5;  // |t_a - t_b| <= tol * max(|t|, tiny)
  // A backend's hit on a triangle the exact ray misses by less than this
  // times the coordinate scale (~16 float ulps) is within float resolution,
  // and so is a miss of a single triangle hit that close to its edge.
  double edge_rel_tol = 0x1p-19;
  // Arbitrate against every triangle the ray's line may cross (not only the
  // two backends' answers) when the scene has at most this many triangles.
  size_t brute_force_limit = 4'000'000;
};

enum class RayVerdict : uint8_t { kAgree, kTie, kBvhRight, kEmbreeRight, kBothRight, kBothWrong };

struct RayDiffResult {
  size_t rays = 0;
  size_t agree = 0;
  size_t ties = 0;
  size_t mismatches = 0;  // = bvh_right + embree_right + both_right + both_wrong
  size_t bvh_right = 0;   // only bvh matches the arbiter
  size_t embree_right = 0;
  size_t both_right = 0;  // both within float resolution of the exact answer
  size_t both_wrong = 0;
  double max_rel_t_error = 0.0;          // agreeing rays, bvh vs embree
  double max_rel_t_error_arbiter = 0.0;  // disputes where bvh is right, bvh vs exact t
  bool brute_force = false;              // arbitrated over the whole scene
  // Answers failing core/hit_check.h (counted among the wrong ones).
  size_t bvh_malformed = 0;
  size_t embree_malformed = 0;
  std::vector<size_t> mismatch_indices;  // increasing
  std::vector<RayVerdict> verdicts;      // one per ray
  size_t bvh_wrong() const { return embree_right + both_wrong; }
};

double rel_t_error(double t, double reference);

// The exact answer over every triangle of the scene the ray's line may cross;
// where a hit lies within the edge tolerance of its border, also over the
// neighbours the line misses by less than that (sure_hit() asks whether the
// triangles at that t cover all around the ray).
ArbiterAnswer arbitrate_scene(const Scene& scene, const Ray& ray, const RayDiffOptions& opts);

// Adds the exact result for triangle `p` to `ans` unless it is there already
// (a backend's hit on a triangle the exact line just misses). `p` must not
// be a closer exact hit than ans's (it is not, when ans comes from
// arbitrate_scene: every exact hit is among its candidates).
void add_candidate(const Scene& scene, const Ray& ray, PrimRef p, ArbiterAnswer& ans);

// Whether one backend's answer is right for `ray` given the arbiter's exact
// answer over a candidate set that contains the backend's primitive:
// a hit must be on a candidate hit (within edge tolerance) at the exact t
// (within t_rel_tol) with no clearly closer sure hit; a miss is right when no
// candidate is surely hit (well inside the interval, and inside its triangle
// by more than the edge tolerance, or near its border where the triangles at
// that t cover all around the ray: a crossing through a shared edge or
// vertex, where a miss is a leak; a silhouette is not).
bool closest_hit_right(const ArbiterAnswer& ans, const Ray& ray, const Hit& hit,
                       const RayDiffOptions& opts, double* rel_err = nullptr);
bool occlusion_right(const ArbiterAnswer& ans, const Ray& ray, bool occluded,
                     const RayDiffOptions& opts);

// Classification without backends (testable on hand-made answers). Runs in
// parallel in the caller's task arena.
RayDiffResult diff_hits(const Scene& scene, std::span<const Ray> rays, std::span<const Hit> bvh,
                        std::span<const Hit> embree, const RayDiffOptions& opts = {});
// Occlusion bytes. When the scene is above brute_force_limit, `bvh_backend`
// and `embree_backend` (if given) supply candidates by tracing the disputed
// rays for their closest hits.
RayDiffResult diff_occlusion(const Scene& scene, std::span<const Ray> rays,
                             std::span<const uint8_t> bvh, std::span<const uint8_t> embree,
                             const RayDiffOptions& opts = {},
                             const Intersector* bvh_backend = nullptr,
                             const Intersector* embree_backend = nullptr);

// Traces `rays` through both (built) backends and diffs them.
RayDiffResult run_ray_diff(const Scene& scene, std::span<const Ray> rays, const Intersector& bvh,
                           const Intersector& embree, bool occluded,
                           const RayDiffOptions& opts = {});

}  // namespace hprt
