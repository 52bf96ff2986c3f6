// What builders see of the scene: one box and one centroid per valid
// triangle, nothing else (builders never touch triangles). `refs` maps a
// builder primitive back to (geomID, primID) so leaves report input indices.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvh/memory/build_array.h"
#include "core/aabb.h"
#include "core/scene.h"

namespace hprt {

struct PrimRef {
  uint32_t geom_id;
  uint32_t prim_id;
  bool operator==(const PrimRef&) const = default;
};

// The arrays are BuildArrays: allocated uninitialised and filled in parallel
// (a std::vector would first initialise tens of MB on one thread).
struct PrimInfo {
  BuildArray<AABB> bounds;
  BuildArray<Vec3f> centroids;
  BuildArray<PrimRef> refs;
  AABB scene_bounds;     // union of `bounds`
  AABB centroid_bounds;  // bounds of the centroids (also when they are not stored)
  size_t invalid = 0;    // triangles left out (degenerate or non-finite)

  size_t size() const { return bounds.size(); }
};

// Valid triangles of every mesh, in (geomID, primID) order. Without
// `store_centroids` the centroids array is left empty (12 bytes a triangle
// neither written nor held): the binned builders take box centres from their
// own references (builder_reads_centroids in builders.h says which need it).
PrimInfo make_prim_info(const Scene& scene, bool store_centroids = true);

}  // namespace hprt
