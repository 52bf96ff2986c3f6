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

void Intersector::intersect_columns(const Scene& scene, const RayInput& rays,
                                    const HitColumns& out) const {
  constexpr size_t kChunk = 65536;  // rays per chunk: the records stay in the caches
  constexpr size_t kGrain = 4096;
  const size_t chunk_size = std::min(rays.size(), kChunk);
  const auto hits = std::make_unique_for_overwrite<Hit[]>(chunk_size);
  // Records are read in place; six-float rays converted a chunk at a time.
  const auto records = rays.records() ? nullptr : std::make_unique_for_overwrite<Ray[]>(chunk_size);
  for (size_t begin = 0; begin < rays.size(); begin += kChunk) {
    const size_t count = std::min(kChunk, rays.size() - begin);
    const Ray* chunk_rays = rays.records() ? rays.records() + begin : records.get();
    if (records)
      tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain),
                        [&](const tbb::blocked_range<size_t>& r) {
                          rays.block(begin + r.begin(), r.size(), records.get() + r.begin());
                        });
    intersect({chunk_rays, count}, {hits.get(), count});
    const HitColumns chunk = out.from(begin);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain),
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
