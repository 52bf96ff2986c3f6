// Intersector::intersect_columns for backends that only answer hit records
// (Embree, plugins): trace a chunk into records, then copy them into the
// columns with each hit's normal from the scene's own triangle.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <memory>

#include "backends/intersector.h"
#include "core/triangle_normal.h"

namespace hprt {

void Intersector::intersect_columns(const Scene& scene, std::span<const Ray> rays,
                                    const HitColumns& out) const {
  constexpr size_t kChunk = 65536;  // rays per chunk: the records stay in the caches
  const auto hits = std::make_unique_for_overwrite<Hit[]>(std::min(rays.size(), kChunk));
  for (size_t begin = 0; begin < rays.size(); begin += kChunk) {
    const size_t count = std::min(kChunk, rays.size() - begin);
    intersect(rays.subspan(begin, count), {hits.get(), count});
    const HitColumns chunk = out.from(begin);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t i = r.begin(); i != r.end(); ++i) {
                          const Hit& h = hits[i];
                          // A plugin's ids are checked (core/hit_check.h); a
                          // miss in any other sense writes no normal.
                          float n[3] = {0.0f, 0.0f, 0.0f};
                          if (chunk.normal && h.hit() && h.geom_id < scene.meshes.size() &&
                              h.prim_id < scene.meshes[h.geom_id].triangle_count())
                            triangle_normal(scene.meshes[h.geom_id], h.prim_id, n);
                          chunk.write(i, h, n);
                        }
                      });
  }
}

}  // namespace hprt
