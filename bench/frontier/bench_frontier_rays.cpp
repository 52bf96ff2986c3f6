// Hard-case and trace rays of the frontier benchmark, and their judging.
#include "bench/frontier/bench_frontier_rays.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <utility>

#include "core/error.h"
#include "core/hit_check.h"
#include "core/parallel.h"
#include "validators/ray_diff.h"
#include "validators/ray_sets.h"

namespace hprt::bench {
namespace {

// The rule of `hprt validate rays`, for the exact answers and the judging alike.
constexpr RayDiffOptions kDiffOptions{};

// Vertex/edge probes, grazing and axis rays on `scene` and on `far`, with
// their exact answers (brute force, in parallel).
void add_hard_sets(FrontierRays& out, const Scene& scene, const Scene& far, size_t n) {
  const std::pair<RayKind, const char*> kinds[] = {{RayKind::kVertexProbe, "probe"},
                                                   {RayKind::kEdgeProbe, "probe"},
                                                   {RayKind::kGrazing, "grazing"},
                                                   {RayKind::kAxis, "axis"}};
  for (const Scene* s : {&scene, &far}) {
    for (const auto& [kind, group] : kinds) {
      HardSet h;
      h.scene = s;
      h.label = std::string(to_string(kind)) + (s == &far ? "@1e6" : "");
      h.group = s == &far ? "offset" : group;
      try {
        h.rays = make_rays(*s, kind, n, 3, nullptr);
      } catch (const InputError& e) {
        out.skipped.push_back(h.label + " (" + e.what() + ")");
        continue;
      }
      h.answers.resize(h.rays.size());
      tbb::parallel_for(tbb::blocked_range<size_t>(0, h.rays.size(), 8),
                        [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i != r.end(); ++i)
                            h.answers[i] = arbitrate_scene(*s, h.rays[i], kDiffOptions);
                        });
      out.hard.push_back(std::move(h));
    }
  }
}

}  // namespace

Scene offset_scene(const Scene& base) {
  Scene s;
  const AABB b = base.bounds();
  const Vec3f c = (b.min + b.max) * 0.5f;
  const Vec3f e = b.max - b.min;
  const float radius = 0.5f * std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
  const float scale = radius > 0 ? 10.0f / radius : 1.0f;
  const Vec3d offset(1e6, -1e6, 1e6);
  for (const auto& m0 : base.meshes) {
    TriangleMesh m = m0;
    for (Vec3f& p : m.positions) p = Vec3f((Vec3d(p) - Vec3d(c)) * double(scale) + offset);
    m.normals.clear();
    s.add_mesh(std::move(m));
  }
  s.camera = base.camera;
  s.lights = base.lights;
  return s;
}

FrontierRays make_frontier_rays(const Scene& scene, const Scene& far, int threads, size_t hard_rays,
                                size_t trace_rays) {
  FrontierRays out;
  run_with_threads(threads, [&] {
    BackendOptions gen_options;
    gen_options.backend = "embree";
    gen_options.threads = threads;
    auto gen = make_intersector("embree", gen_options);
    gen->build(scene);
    out.trace = make_rays(scene, RayKind::kPrimary, trace_rays, 1, gen.get());
    const std::vector<Ray> random = make_rays(scene, RayKind::kRandom, trace_rays, 2, gen.get());
    out.trace.insert(out.trace.end(), random.begin(), random.end());
    add_hard_sets(out, scene, far, hard_rays);
  });
  for (const auto& s : out.hard) out.hard_total += s.rays.size();
  return out;
}

// A hit on a triangle outside the brute-force candidates (the exact line
// misses it, e.g. by 1e-9 beside a shared edge) is judged with that triangle
// added, as arbitrate_dispute() in ray_diff.cpp does: within the edge
// tolerance it is right.
size_t count_wrong(const HardSet& set, const Intersector& b) {
  std::vector<Hit> hits(set.rays.size());
  b.intersect(set.rays, hits);
  size_t wrong = 0;
  for (size_t i = 0; i < set.rays.size(); ++i) {
    const ArbiterAnswer& ans = set.answers[i];
    const Hit& h = hits[i];
    bool right;
    if (!hit_well_formed(*set.scene, set.rays[i], h)) {
      right = false;  // a plugin's malformed answer (core/hit_check.h)
    } else if (h.hit()) {
      ArbiterAnswer with_hit = ans;
      add_candidate(*set.scene, set.rays[i], PrimRef{h.geom_id, h.prim_id}, with_hit);
      right = closest_hit_right(with_hit, set.rays[i], h, kDiffOptions);
    } else {
      right = closest_hit_right(ans, set.rays[i], h, kDiffOptions);
    }
    if (!right) ++wrong;
  }
  return wrong;
}

}  // namespace hprt::bench
