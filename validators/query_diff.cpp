// The query diff (see query_diff.h).
#include "validators/query_diff.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdio>
#include <limits>

#include "bvh/intersect/ray_triangle.h"
#include "core/exact_predicates.h"
#include "core/splitmix64.h"
#include "validators/arbiter.h"

namespace hprt {
namespace {

const Vec3f* triangle_of(const Scene& scene, PrimRef r, Vec3f (&v)[3]) {
  const TriangleMesh& m = scene.meshes[r.geom_id];
  const Vec3u& t = m.triangles[r.prim_id];
  for (int k = 0; k < 3; ++k) v[k] = m.positions[t[k]];
  return v;
}

// Indices where the two answers differ (`same(a[i], b[i])` false).
template <typename T, typename Same>
std::vector<size_t> disputed_indices(const std::vector<T>& a, const std::vector<T>& b,
                                     Same&& same) {
  std::vector<size_t> disputed;
  for (size_t i = 0; i < a.size(); ++i)
    if (!same(a[i], b[i])) disputed.push_back(i);
  return disputed;
}

const auto equal = [](const auto& x, const auto& y) { return x == y; };

// Sorts out each disagreement (indices in `disputed`) with `judge(i)`, which
// returns {backend right, reference right}, in parallel.
template <typename Judge>
void settle(QueryDiffResult& r, const std::vector<size_t>& disputed, const Scene& scene,
            const QueryDiffOptions& opts, Judge&& judge) {
  r.mismatches = disputed.size();
  r.mismatch_indices = disputed;
  r.agree = r.queries - disputed.size();
  if (scene.triangle_count() > opts.brute_force_limit) {
    r.unjudged = disputed.size();
    return;
  }
  std::vector<uint8_t> verdict(disputed.size());
  tbb::parallel_for(size_t(0), disputed.size(), [&](size_t k) {
    const auto [a, b] = judge(disputed[k]);
    verdict[k] = uint8_t(a) | uint8_t(b) << 1;
  });
  for (uint8_t v : verdict) {
    r.backend_right += v == 1;
    r.reference_right += v == 2;
    r.both_right += v == 3;
    r.both_wrong += v == 0;
  }
}

}  // namespace

std::string_view to_string(QueryKind kind) {
  switch (kind) {
    case QueryKind::kCount:
      return "count";
    case QueryKind::kInside:
      return "inside";
    case QueryKind::kClosest:
      return "closest";
  }
  return "?";
}

uint32_t exact_count(const Scene& scene, const Ray& ray, bool* through_edge) {
  if (through_edge) *through_edge = false;
  if (!arbiter_ray_valid(ray)) return 0;
  const std::vector<PrimRef> candidates = line_candidates(scene, ray);
  uint32_t n = 0;
  bool edge = false;
  for (PrimRef p : candidates) {
    Vec3f v[3];
    triangle_of(scene, p, v);
    const CandidateResult c = arbitrate_triangle(ray, v[0], v[1], v[2]);
    n += c.hit;
    edge = edge || (c.hit && c.zero_edges > 0);
  }
  if (!edge) return n;
  // No unique count: the fill rule, triangle by triangle.
  if (through_edge) *through_edge = true;
  const WatertightTest::Prepared prep = WatertightTest::prepare(ray);
  n = 0;
  for (PrimRef p : candidates) {
    Vec3f v[3];
    triangle_of(scene, p, v);
    if (!scene.meshes[p.geom_id].triangle_valid(p.prim_id)) continue;
    TriangleHit h;
    n += WatertightTest::intersect(prep, v[0], v[1], v[2], ray.tnear, ray.tfar, h);
  }
  return n;
}

PointLocation exact_location(const Scene& scene, const Vec3f& p, uint64_t seed) {
  for (size_t a = 0; a < 3; ++a)
    if (!(std::fabs(p[int(a)]) <= kRayComponentLimit)) return PointLocation::kOutside;
  for (const TriangleMesh& m : scene.meshes)
    for (size_t i = 0; i < m.triangle_count(); ++i) {
      if (!m.triangle_valid(i)) continue;
      const Vec3u& t = m.triangles[i];
      if (exact::on_triangle(m.positions[t[0]], m.positions[t[1]], m.positions[t[2]], p))
        return PointLocation::kOnSurface;
    }
  SplitMix64 rng(seed);
  for (;;) {
    Ray r;
    r.org = p;
    r.dir = Vec3f{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f};
    r.tnear = 0.0f;
    r.tfar = std::numeric_limits<float>::infinity();
    if (r.dir == Vec3f{0, 0, 0}) continue;
    bool edge = false;
    const uint32_t n = exact_count(scene, r, &edge);
    if (!edge) return n % 2 ? PointLocation::kInside : PointLocation::kOutside;
  }
}

ClosestPoint exact_closest(const Scene& scene, const Vec3f& p, float max_distance) {
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(p[a]) <= kRayComponentLimit)) return {};
  double best = closest_search_d2(max_distance);
  uint32_t bg = kInvalidId, bp = kInvalidId;
  TrianglePoint at{};
  for (uint32_t g = 0; g < scene.meshes.size(); ++g) {
    const TriangleMesh& m = scene.meshes[g];
    for (uint32_t i = 0; i < m.triangle_count(); ++i) {
      if (!m.triangle_valid(i)) continue;
      const Vec3u& t = m.triangles[i];
      const TrianglePoint q =
          closest_point_on_triangle(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]);
      if (closest_before(q.d2, g, i, best, bg, bp)) {
        best = q.d2;
        bg = g;
        bp = i;
        at = q;
      }
    }
  }
  if (bg == kInvalidId) return {};
  return keep_within(to_closest_point(at, bg, bp), max_distance);
}

namespace {

// The diff of one query kind: answer(intersector, out) fills one T per
// query on each side; exact(i) is the right answer of query i (judged only
// where the two sides differ by `same`).
template <typename T, typename Answer, typename Same, typename Exact>
QueryDiffResult run_diff(QueryKind kind, size_t queries, const Scene& scene,
                         const Intersector& backend, const Intersector& reference,
                         const QueryDiffOptions& opts, Answer&& answer, Same&& same,
                         Exact&& exact) {
  QueryDiffResult r;
  r.kind = kind;
  r.queries = queries;
  std::vector<T> a(queries), b(queries);
  answer(backend, a);
  answer(reference, b);
  settle(r, disputed_indices(a, b, same), scene, opts, [&](size_t i) {
    const T e = exact(i);
    return std::pair<bool, bool>{same(a[i], e), same(b[i], e)};
  });
  return r;
}

}  // namespace

QueryDiffResult run_count_diff(const Scene& scene, std::span<const Ray> rays,
                               const Intersector& backend, const Intersector& reference,
                               const QueryDiffOptions& opts) {
  std::atomic<size_t> fill_rule{0};
  QueryDiffResult r = run_diff<uint32_t>(
      QueryKind::kCount, rays.size(), scene, backend, reference, opts,
      [&](const Intersector& x, std::vector<uint32_t>& out) { x.count(rays, out); }, equal,
      [&](size_t i) {
        bool through_edge = false;
        const uint32_t n = exact_count(scene, rays[i], &through_edge);
        fill_rule += through_edge;
        return n;
      });
  r.fill_rule = fill_rule;
  return r;
}

QueryDiffResult run_inside_diff(const Scene& scene, std::span<const Vec3f> points,
                                const Intersector& backend, const Intersector& reference,
                                const QueryDiffOptions& opts) {
  return run_diff<PointLocation>(
      QueryKind::kInside, points.size(), scene, backend, reference, opts,
      [&](const Intersector& x, std::vector<PointLocation>& out) { x.locate(points, out); }, equal,
      [&](size_t i) { return exact_location(scene, points[i], 1000 + i); });
}

QueryDiffResult run_closest_diff(const Scene& scene, std::span<const Vec3f> points,
                                 const Intersector& backend, const Intersector& reference,
                                 const QueryDiffOptions& opts) {
  const auto same = [](const ClosestPoint& x, const ClosestPoint& y) {
    return x.geom_id == y.geom_id && x.prim_id == y.prim_id && x.distance == y.distance;
  };
  return run_diff<ClosestPoint>(
      QueryKind::kClosest, points.size(), scene, backend, reference, opts,
      [&](const Intersector& x, std::vector<ClosestPoint>& out) {
        x.closest(points, opts.max_distance, out);
      },
      same, [&](size_t i) { return exact_closest(scene, points[i], opts.max_distance); });
}

std::string query_diff_summary(const QueryDiffResult& r, const std::string& backend,
                               const std::string& reference, const std::string& source) {
  const std::string q(to_string(r.kind));
  char buf[512];
  std::string s;
  std::snprintf(buf, sizeof buf, "hprt validate query: %s, %zu %s (%s)\n", q.c_str(), r.queries,
                r.kind == QueryKind::kCount ? "rays" : "points", source.c_str());
  s += buf;
  std::snprintf(buf, sizeof buf, "  %s vs %s: %zu agree, %zu disagree\n", backend.c_str(),
                reference.c_str(), r.agree, r.mismatches);
  s += buf;
  if (r.mismatches > 0) {
    std::snprintf(buf, sizeof buf,
                  "  exact judge: %s right %zu, %s right %zu, both right %zu, both wrong %zu, "
                  "not judged %zu\n",
                  backend.c_str(), r.backend_right, reference.c_str(), r.reference_right,
                  r.both_right, r.both_wrong, r.unjudged);
    s += buf;
  }
  if (r.fill_rule > 0) {
    std::snprintf(buf, sizeof buf,
                  "  %zu disputed rays pass exactly through an edge or vertex: judged by the fill "
                  "rule\n",
                  r.fill_rule);
    s += buf;
  }
  std::snprintf(
      buf, sizeof buf, "  %s: %s (%zu wrong%s)\n", backend.c_str(),
      r.backend_wrong() == 0 ? (r.unjudged == 0 ? "PASS" : "PASS (unjudged remain)") : "FAIL",
      r.backend_wrong(), r.unjudged ? ", disagreements above the brute-force limit" : "");
  s += buf;
  return s;
}

}  // namespace hprt
