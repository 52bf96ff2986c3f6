// Intersector::intersect_normals for backends that only answer hits (Embree,
// plugins): trace, then each hit's normal from the scene's own triangle.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>

#include "backends/intersector.h"
#include "core/triangle_normal.h"

namespace hprt {

void Intersector::intersect_normals(const Scene& scene, std::span<const Ray> rays,
                                    std::span<Hit> hits, std::span<float> normals) const {
  if (hits.size() < rays.size() || normals.size() < 3 * rays.size())
    throw std::invalid_argument("intersect_normals: fewer result slots than rays");
  intersect(rays, hits);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        float* n = normals.data() + 3 * i;
                        const Hit& h = hits[i];
                        if (!h.hit() || h.geom_id >= scene.meshes.size() ||
                            h.prim_id >= scene.meshes[h.geom_id].triangle_count()) {
                          n[0] = n[1] = n[2] = 0.0f;
                          continue;
                        }
                        triangle_normal(scene.meshes[h.geom_id], h.prim_id, n);
                      }
                    });
}

}  // namespace hprt
