// The query diff: the count, inside and closest queries through two
// backends (the one under test and the reference), every disagreement
// settled by an exact judge over the whole scene (brute force):
//   count:   the number of triangles the ray exactly crosses in (tnear, tfar]
//            (the arbiter); a ray exactly through an edge or vertex has no
//            unique count, and there the fill rule applied triangle by
//            triangle (the scalar exact test, no traversal) decides;
//   inside:  exactly on a triangle (exact predicates), else the parity of
//            the arbiter's crossings of random rays from the point, redrawn
//            until one passes no edge or vertex exactly;
//   closest: the brute-force search with the same double formula and tie
//            rule (core/point_query.h): the distance must be equal and the
//            triangle the one the tie rule names.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "core/point_query.h"
#include "core/ray.h"
#include "core/scene.h"

namespace hprt {

enum class QueryKind { kCount, kInside, kClosest };
std::string_view to_string(QueryKind kind);

struct QueryDiffOptions {
  // Judge disagreements when the scene has at most this many triangles
  // (each judgement is a pass over all of them).
  size_t brute_force_limit = 4'000'000;
  float max_distance = HUGE_VALF;  // closest
};

struct QueryDiffResult {
  QueryKind kind = QueryKind::kCount;
  size_t queries = 0;
  size_t agree = 0;
  size_t mismatches = 0;  // = backend_right + reference_right + both_right + both_wrong + unjudged
  size_t backend_right = 0;    // only the backend under test matches the judge
  size_t reference_right = 0;  // only the reference does
  size_t both_right = 0;       // closest: both name a triangle at the exact distance
  size_t both_wrong = 0;
  size_t unjudged = 0;                   // the scene is above the brute-force limit
  size_t fill_rule = 0;                  // count: disputed rays exactly through an edge or vertex
  std::vector<size_t> mismatch_indices;  // increasing
  size_t backend_wrong() const { return reference_right + both_wrong; }
};

// The exact judges, one query each (O(triangles)).
uint32_t exact_count(const Scene& scene, const Ray& ray, bool* through_edge = nullptr);
PointLocation exact_location(const Scene& scene, const Vec3f& p, uint64_t seed);
ClosestPoint exact_closest(const Scene& scene, const Vec3f& p, float max_distance);

// Runs the query through both (built) backends and diffs them, in parallel
// in the caller's task arena.
QueryDiffResult run_count_diff(const Scene& scene, std::span<const Ray> rays,
                               const Intersector& backend, const Intersector& reference,
                               const QueryDiffOptions& opts = {});
QueryDiffResult run_inside_diff(const Scene& scene, std::span<const Vec3f> points,
                                const Intersector& backend, const Intersector& reference,
                                const QueryDiffOptions& opts = {});
QueryDiffResult run_closest_diff(const Scene& scene, std::span<const Vec3f> points,
                                 const Intersector& backend, const Intersector& reference,
                                 const QueryDiffOptions& opts = {});

// The text `hprt validate query` prints: counts per verdict and the
// pass/fail line for the backend under test. Lines end in '\n'.
std::string query_diff_summary(const QueryDiffResult& r, const std::string& backend,
                               const std::string& reference, const std::string& source);

}  // namespace hprt
