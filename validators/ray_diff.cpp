// Ray diff classification and judging against the exact arbiter; rays are
// classified in parallel (oneTBB, caller's arena), counts summed afterwards.
#include "validators/ray_diff.h"

#include "core/hit_check.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hprt {
namespace {

constexpr double kTinyT = 1e-20;

double tol(double t, const RayDiffOptions& o) {
  return o.t_rel_tol * std::max(std::fabs(t), kTinyT);
}

// Tolerance on a candidate's t: relative, plus the t change of an offset of
// the plane by the edge tolerance (float rounding of grazing rays).
double ctol(const CandidateResult& c, const RayDiffOptions& o) {
  return tol(c.t, o) + o.edge_rel_tol * c.scale * c.t_per_distance;
}

// Possibly hit within float resolution: inside up to the edge tolerance and
// t inside the interval up to the t tolerance.
bool near_hit(const CandidateResult& c, const Ray& ray, const RayDiffOptions& o) {
  if (!c.valid || !std::isfinite(c.t)) return false;
  if (!(c.margin >= -o.edge_rel_tol * c.scale)) return false;
  return c.t > double(ray.tnear) - ctol(c, o) && c.t <= double(ray.tfar) + ctol(c, o);
}

// Whether (x, y) lies in the closed projected triangle, up to `slack` world
// units outside it. A triangle seen edge-on covers no area and never counts.
bool projected_contains(const CandidateResult& c, double x, double y, double slack) {
  const double(&p)[3][2] = c.proj;
  const double area =
      (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
  if (!(std::fabs(area) > 0.0)) return false;
  for (int i = 0; i < 3; ++i) {
    const double* a = p[i];
    const double* b = p[(i + 1) % 3];
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    const double len = std::hypot(ex, ey);
    if (len == 0.0) return false;
    const double side = (ex * (y - a[1]) - ey * (x - a[0])) * (area > 0 ? 1.0 : -1.0);
    if (side / len < -slack) return false;
  }
  return true;
}

// Whether the triangles of `group` cover every point at distance r / 2 from
// the ray's line (32 directions) and the line itself: then every ray within
// float resolution crosses the surface there, so a miss is a leak. At a
// silhouette (a fold seen edge-on, a vertex whose fan folds over as seen from
// the ray) some nearby rays pass outside, and a miss is within resolution.
bool covers_around_line(const std::vector<const CandidateResult*>& group, double r) {
  constexpr int kDirections = 32;
  const double slack = 1e-6 * r;
  for (int k = -1; k < kDirections; ++k) {
    const double angle = 2.0 * M_PI * k / kDirections;
    const double x = k < 0 ? 0.0 : 0.5 * r * std::cos(angle);
    const double y = k < 0 ? 0.0 : 0.5 * r * std::sin(angle);
    bool covered = false;
    for (const CandidateResult* c : group) covered = covered || projected_contains(*c, x, y, slack);
    if (!covered) return false;
  }
  return true;
}

// Surely hit: an exact hit well inside the interval, and inside its triangle
// by more than the edge tolerance r, or near an edge or vertex where the
// triangles at the same t cover all around the ray's line (a crossing through
// an edge or vertex between triangles: missing all of them is a leak).
bool sure_hit(const ArbiterAnswer& ans, size_t i, const Ray& ray, const RayDiffOptions& o) {
  const CandidateResult& c = ans.candidates[i];
  if (!c.hit) return false;
  if (!(c.t >= double(ray.tnear) + ctol(c, o) && c.t <= double(ray.tfar) - ctol(c, o)))
    return false;
  return c.margin >= o.edge_rel_tol * c.scale || c.surrounded;
}

// Sets `surrounded` on each hit within the edge tolerance r of its border.
void mark_surrounded(ArbiterAnswer& ans, const RayDiffOptions& o) {
  std::vector<const CandidateResult*> group;
  for (CandidateResult& c : ans.candidates) {
    const double r = o.edge_rel_tol * c.scale;
    if (!c.hit || c.margin >= r) continue;
    group.clear();
    for (const CandidateResult& d : ans.candidates)
      if (d.valid && std::isfinite(d.t) && d.margin >= -r && std::fabs(d.t - c.t) <= ctol(c, o))
        group.push_back(&d);
    c.surrounded = covers_around_line(group, r);
  }
}

void add_unique(std::vector<PrimRef>& v, PrimRef p) {
  if (std::find(v.begin(), v.end(), p) == v.end()) v.push_back(p);
}

PrimRef ref_of(const Hit& h) { return {h.geom_id, h.prim_id}; }

// Whether some exact hit lies within the edge tolerance of its triangle's
// border: only then does sure_hit() need the neighbours the line just misses.
bool needs_neighbours(const ArbiterAnswer& ans, const RayDiffOptions& o) {
  for (const CandidateResult& c : ans.candidates)
    if (c.hit && c.margin < o.edge_rel_tol * c.scale) return true;
  return false;
}

ArbiterAnswer arbitrate_dispute(const Scene& scene, const Ray& ray, const Hit* a, const Hit* b,
                                bool brute_force, const RayDiffOptions& o) {
  std::vector<PrimRef> given;
  if (a && a->hit()) add_unique(given, ref_of(*a));
  if (b && b->hit()) add_unique(given, ref_of(*b));
  if (!brute_force) {
    ArbiterAnswer ans = arbitrate(scene, ray, given);
    mark_surrounded(ans, o);
    return ans;
  }
  ArbiterAnswer ans = arbitrate_scene(scene, ray, o);
  for (PrimRef p : given) add_candidate(scene, ray, p, ans);
  return ans;
}

void tally(RayDiffResult& r) {
  for (size_t i = 0; i < r.verdicts.size(); ++i) {
    switch (r.verdicts[i]) {
      case RayVerdict::kAgree:
        ++r.agree;
        break;
      case RayVerdict::kTie:
        ++r.ties;
        break;
      case RayVerdict::kBvhRight:
        ++r.bvh_right;
        break;
      case RayVerdict::kEmbreeRight:
        ++r.embree_right;
        break;
      case RayVerdict::kBothRight:
        ++r.both_right;
        break;
      case RayVerdict::kBothWrong:
        ++r.both_wrong;
        break;
    }
    if (r.verdicts[i] != RayVerdict::kAgree && r.verdicts[i] != RayVerdict::kTie)
      r.mismatch_indices.push_back(i);
  }
  r.mismatches = r.mismatch_indices.size();
}

RayVerdict verdict(bool bvh_ok, bool embree_ok) {
  if (bvh_ok && embree_ok) return RayVerdict::kBothRight;
  if (bvh_ok) return RayVerdict::kBvhRight;
  if (embree_ok) return RayVerdict::kEmbreeRight;
  return RayVerdict::kBothWrong;
}

// Per-ray maxima gathered without locks: one slot per ray.
double max_of(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, x);
  return m;
}

}  // namespace

ArbiterAnswer arbitrate_scene(const Scene& scene, const Ray& ray, const RayDiffOptions& o) {
  ArbiterAnswer ans = arbitrate_brute_force(scene, ray);
  if (!needs_neighbours(ans, o)) return ans;
  // Coverage is sampled at r / 2 from the line (covers_around_line), so the
  // neighbours within a little more than that are enough; once marked, the
  // ones the line misses are dropped (there may be hundreds at 1e6).
  ans = arbitrate_brute_force(scene, ray, 0.5001 * o.edge_rel_tol);
  mark_surrounded(ans, o);
  std::erase_if(ans.candidates, [](const CandidateResult& c) { return !c.hit; });
  ans.candidates.shrink_to_fit();
  return ans;
}

void add_candidate(const Scene& scene, const Ray& ray, PrimRef p, ArbiterAnswer& ans) {
  if (std::any_of(ans.candidates.begin(), ans.candidates.end(),
                  [&](const CandidateResult& c) { return c.prim == p; }))
    return;
  const PrimRef one[] = {p};
  const ArbiterAnswer a = arbitrate(scene, ray, one);
  ans.candidates.push_back(a.candidates.front());
}

double rel_t_error(double t, double reference) {
  return std::fabs(t - reference) / std::max(std::fabs(reference), kTinyT);
}

bool closest_hit_right(const ArbiterAnswer& ans, const Ray& ray, const Hit& hit,
                       const RayDiffOptions& o, double* rel_err) {
  if (!hit.hit()) {
    for (size_t i = 0; i < ans.candidates.size(); ++i)
      if (sure_hit(ans, i, ray, o)) return false;
    return true;
  }
  const PrimRef p = ref_of(hit);
  const auto it = std::find_if(ans.candidates.begin(), ans.candidates.end(),
                               [&](const CandidateResult& c) { return c.prim == p; });
  if (it == ans.candidates.end() || !near_hit(*it, ray, o)) return false;
  const double err = rel_t_error(double(hit.t), it->t);
  if (rel_err) *rel_err = err;
  if (std::fabs(double(hit.t) - it->t) > ctol(*it, o)) return false;
  for (size_t i = 0; i < ans.candidates.size(); ++i)
    if (sure_hit(ans, i, ray, o) && ans.candidates[i].t < it->t - ctol(*it, o)) return false;
  return true;
}

bool occlusion_right(const ArbiterAnswer& ans, const Ray& ray, bool occluded,
                     const RayDiffOptions& o) {
  for (size_t i = 0; i < ans.candidates.size(); ++i) {
    if (occluded && near_hit(ans.candidates[i], ray, o)) return true;
    if (!occluded && sure_hit(ans, i, ray, o)) return false;
  }
  return !occluded;
}

RayDiffResult diff_hits(const Scene& scene, std::span<const Ray> rays, std::span<const Hit> bvh,
                        std::span<const Hit> embree, const RayDiffOptions& o) {
  RayDiffResult r;
  r.rays = rays.size();
  r.brute_force = scene.triangle_count() <= o.brute_force_limit;
  r.verdicts.resize(rays.size());
  std::vector<double> agree_err(rays.size(), 0.0), dispute_err(rays.size(), 0.0);
  std::vector<uint8_t> malformed_b(rays.size(), 0), malformed_e(rays.size(), 0);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, rays.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
          const Hit& b = bvh[i];
          const Hit& e = embree[i];
          // A malformed answer is wrong whatever the arbiter says, and its
          // ids are not used (they may name no triangle).
          const bool bbad = !hit_well_formed(scene, rays[i], b);
          const bool ebad = !hit_well_formed(scene, rays[i], e);
          if (bbad || ebad) {
            malformed_b[i] = bbad;
            malformed_e[i] = ebad;
            const ArbiterAnswer ans = arbitrate_dispute(scene, rays[i], bbad ? nullptr : &b,
                                                        ebad ? nullptr : &e, r.brute_force, o);
            r.verdicts[i] = verdict(!bbad && closest_hit_right(ans, rays[i], b, o),
                                    !ebad && closest_hit_right(ans, rays[i], e, o));
            continue;
          }
          if (!b.hit() && !e.hit()) {
            r.verdicts[i] = RayVerdict::kAgree;
            continue;
          }
          const bool same_t =
              b.hit() && e.hit() && std::fabs(double(b.t) - double(e.t)) <= tol(double(e.t), o);
          if (same_t && ref_of(b) == ref_of(e)) {
            r.verdicts[i] = RayVerdict::kAgree;
            agree_err[i] = rel_t_error(b.t, e.t);
            continue;
          }
          const ArbiterAnswer ans = arbitrate_dispute(scene, rays[i], &b, &e, r.brute_force, o);
          double err = 0.0;
          const bool bok = closest_hit_right(ans, rays[i], b, o, &err);
          const bool eok = closest_hit_right(ans, rays[i], e, o);
          if (bok && b.hit()) dispute_err[i] = err;
          r.verdicts[i] = same_t && bok && eok ? RayVerdict::kTie : verdict(bok, eok);
        }
      });
  r.max_rel_t_error = max_of(agree_err);
  r.max_rel_t_error_arbiter = max_of(dispute_err);
  r.bvh_malformed = size_t(std::count(malformed_b.begin(), malformed_b.end(), uint8_t(1)));
  r.embree_malformed = size_t(std::count(malformed_e.begin(), malformed_e.end(), uint8_t(1)));
  tally(r);
  return r;
}

RayDiffResult diff_occlusion(const Scene& scene, std::span<const Ray> rays,
                             std::span<const uint8_t> bvh, std::span<const uint8_t> embree,
                             const RayDiffOptions& o, const Intersector* bvh_backend,
                             const Intersector* embree_backend) {
  RayDiffResult r;
  r.rays = rays.size();
  r.brute_force = scene.triangle_count() <= o.brute_force_limit;
  r.verdicts.assign(rays.size(), RayVerdict::kAgree);
  std::vector<size_t> disputed;
  for (size_t i = 0; i < rays.size(); ++i) {
    const bool bad = !occlusion_well_formed(bvh[i]) || !occlusion_well_formed(embree[i]);
    r.bvh_malformed += !occlusion_well_formed(bvh[i]);
    r.embree_malformed += !occlusion_well_formed(embree[i]);
    if (bad || (bvh[i] != 0) != (embree[i] != 0)) disputed.push_back(i);
  }
  // Closest hits of the disputed rays as candidates (needed without brute force).
  std::vector<Ray> sub(disputed.size());
  for (size_t k = 0; k < disputed.size(); ++k) sub[k] = rays[disputed[k]];
  std::vector<Hit> hb(sub.size()), he(sub.size());
  if (bvh_backend) bvh_backend->intersect(sub, hb);
  if (embree_backend) embree_backend->intersect(sub, he);
  tbb::parallel_for(size_t(0), disputed.size(), [&](size_t k) {
    const size_t i = disputed[k];
    const bool bok = hit_well_formed(scene, rays[i], hb[k]);
    const bool eok = hit_well_formed(scene, rays[i], he[k]);
    const ArbiterAnswer ans = arbitrate_dispute(scene, rays[i], bok ? &hb[k] : nullptr,
                                                eok ? &he[k] : nullptr, r.brute_force, o);
    r.verdicts[i] = verdict(
        occlusion_well_formed(bvh[i]) && occlusion_right(ans, rays[i], bvh[i] != 0, o),
        occlusion_well_formed(embree[i]) && occlusion_right(ans, rays[i], embree[i] != 0, o));
  });
  tally(r);
  return r;
}

RayDiffResult run_ray_diff(const Scene& scene, std::span<const Ray> rays, const Intersector& bvh,
                           const Intersector& embree, bool occluded, const RayDiffOptions& o) {
  if (occluded) {
    std::vector<uint8_t> ob(rays.size()), oe(rays.size());
    bvh.occluded(rays, ob);
    embree.occluded(rays, oe);
    return diff_occlusion(scene, rays, ob, oe, o, &bvh, &embree);
  }
  std::vector<Hit> hb(rays.size()), he(rays.size());
  bvh.intersect(rays, hb);
  embree.intersect(rays, he);
  return diff_hits(scene, rays, hb, he, o);
}

}  // namespace hprt
