// What builders see of the scene: one box (and, for the builders that read
// them, one centroid) per valid triangle, nothing else (builders never touch
// triangles); the boxes may be released after a build (release_bounds).
// `refs` maps a builder primitive back to (geomID, primID) so leaves report
// input indices.
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

// Triangle i's box: its three vertices extended into an empty box, in
// order (make_prim_info's box, and PrimInfo::box's once `bounds` is released).
inline AABB triangle_box(const TriangleMesh& m, size_t i) {
  const Vec3u& t = m.triangles[i];
  AABB b;
  b.extend(m.positions[t[0]]);
  b.extend(m.positions[t[1]]);
  b.extend(m.positions[t[2]]);
  return b;
}

// The arrays are BuildArrays: allocated uninitialised and filled in parallel
// (a std::vector would first initialise tens of MB on one thread).
struct PrimInfo {
  BuildArray<AABB> bounds;  // empty once released (release_bounds)
  BuildArray<Vec3f> centroids;
  BuildArray<PrimRef> refs;
  AABB scene_bounds;     // union of the boxes
  AABB centroid_bounds;  // bounds of the centroids (also when they are not stored)
  size_t invalid = 0;    // triangles left out (degenerate or non-finite)

  size_t size() const { return refs.size(); }

  // Box i: from `bounds` while held, else the same bits again from the
  // scene's triangle (`scene` is the one the info was made from).
  AABB box(size_t i, const Scene& scene) const {
    if (!bounds.empty()) return bounds[i];
    const PrimRef r = refs[i];
    return triangle_box(scene.meshes[r.geom_id], r.prim_id);
  }
  // Frees `bounds` (24 bytes a primitive): the binned builders do once
  // their references hold the boxes (build_tree_releasing_bounds), so a
  // build's peak memory does not hold both.
  void release_bounds() { bounds = BuildArray<AABB>(); }
};

// Valid triangles of every mesh, in (geomID, primID) order. Without
// `store_centroids` the centroids array is left empty (12 bytes a triangle
// neither written nor held): the binned builders take box centres from their
// own references (builder_reads_centroids in builders.h says which need it).
PrimInfo make_prim_info(const Scene& scene, bool store_centroids = true);

}  // namespace hprt
