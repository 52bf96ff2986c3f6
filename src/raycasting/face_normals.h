#pragma once
// Unit geometric normals of every triangle of a scene (api::Scene::normals),
// for the primitive_normals of compute_closest_points (cast_rays has the
// backend write them during the trace).
//
// Made once per scene state (the RaycastingScene drops it when triangles are
// added or moved): a closest point's normal is then one 12-byte read of a
// random triangle instead of an index triple and three vertices, a chain of
// dependent cache misses on a large mesh. 12 bytes per triangle.
#include <hprt/hprt.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace hprt::raycasting {

class FaceNormals {
 public:
  // Each triangle's unit normal, zero for a degenerate one; parallel over
  // the triangles.
  explicit FaceNormals(const api::Scene& scene);

  // Writes the normal of triangle (geom_id(i), prim_id(i)) to out(i) (a
  // float[3]) for every i in [begin, end); prim_id kInvalidId gives zero.
  template <typename GeomId, typename PrimId, typename Out>
  void write(size_t begin, size_t end, GeomId&& geom_id, PrimId&& prim_id, Out&& out) const {
    constexpr size_t kAhead = 64;  // items between a request and its use (random reads)
    for (size_t i = begin; i < end; ++i) {
      if (i + kAhead < end) {
        const uint32_t p = prim_id(i + kAhead);
        if (p != api::kInvalidId) __builtin_prefetch(normal(geom_id(i + kAhead), p));
      }
      float* n = out(i);
      const uint32_t p = prim_id(i);
      if (p == api::kInvalidId) {
        n[0] = n[1] = n[2] = 0.0f;
        continue;
      }
      const float* src = normal(geom_id(i), p);
      n[0] = src[0], n[1] = src[1], n[2] = src[2];
    }
  }

  size_t memory_bytes() const { return 3 * sizeof(float) * triangles_; }

 private:
  const float* normal(uint32_t geom_id, uint32_t prim_id) const {
    return normals_.get() + 3 * (first_[geom_id] + prim_id);
  }

  std::vector<size_t> first_;  // index of each geometry's first triangle
  size_t triangles_ = 0;
  std::unique_ptr<float[]> normals_;
};

}  // namespace hprt::raycasting
