#include "workload/surface_hits.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/hit.h"
#include "workload/workload_rays.h"

namespace hprt {

std::vector<SurfaceHit> primary_surface_hits(const Scene& scene, size_t n, SplitMix64& rng,
                                             const Intersector* backend, std::string_view kind) {
  if (!backend) throw std::invalid_argument(std::string(kind) + " rays need a backend");
  std::vector<SurfaceHit> out;
  out.reserve(n);
  std::vector<Hit> hits;
  std::vector<size_t> hit_index;
  size_t traced = 0, found = 0;
  // Each round traces enough fresh primary rays for the hit rate seen so far
  // (bounded rounds).
  for (int round = 0; round < 16 && out.size() < n; ++round) {
    const size_t need = n - out.size();
    const double rate = traced ? std::max(double(found) / double(traced), 0.01) : 0.5;
    const size_t want =
        std::min<size_t>(size_t(double(need) * 1.25 / rate) + 1024, size_t(1) << 26);
    const std::vector<Ray> rays = primary_rays(scene, want, rng);
    hits.resize(rays.size());
    backend->intersect(rays, hits);
    hit_index.clear();
    for (size_t i = 0; i < rays.size(); ++i) {
      const Hit& h = hits[i];
      if (!h.hit() || h.geom_id >= scene.meshes.size()) continue;
      const TriangleMesh& m = scene.meshes[h.geom_id];
      if (h.prim_id < m.triangles.size() && m.triangle_valid(h.prim_id)) hit_index.push_back(i);
    }
    traced += rays.size();
    found += hit_index.size();
    // Take hits evenly over the image (scanline order) when there are more
    // than needed, so the set covers the whole view, not its top rows.
    const size_t take = std::min(need, hit_index.size());
    for (size_t k = 0; k < take; ++k) {
      const size_t i = hit_index[size_t(double(k) * double(hit_index.size()) / double(take))];
      const Hit& h = hits[i];
      const TriangleMesh& m = scene.meshes[h.geom_id];
      const Vec3u& t = m.triangles[h.prim_id];
      const Vec3d a(m.positions[t[0]]), b(m.positions[t[1]]), c(m.positions[t[2]]);
      const double u = h.u, v = h.v;
      const Vec3f p(a * (1.0 - u - v) + b * u + c * v);
      Vec3f nrm = Vec3f(normalize(cross(b - a, c - a)));
      if (dot(nrm, rays[i].dir) > 0.0f) nrm = -nrm;
      out.push_back({p, nrm, rays[i].dir});
    }
  }
  if (out.size() < n)
    throw OptionError("kind", std::string(kind) + ": only " + std::to_string(out.size()) + " of " +
                                  std::to_string(n) +
                                  " primary rays hit the scene (camera misses it?)");
  return out;
}

}  // namespace hprt
