// Triangles reordered into leaf order (a leaf covers [first, first + count)),
// with the data each ray/triangle test reads precomputed, one array per test
// so a leaf's triangles are contiguous for the test in use (a 4-triangle leaf
// is 144 bytes: 2-3 cache lines, instead of 3-6 with one array per vertex):
//   verts: the raw v0, v1, v2 for the watertight test (v0 + e1 would not
//          reproduce v1 exactly, and watertightness needs the exact vertices);
//   edges: v0, e1 = v1 - v0, e2 = v2 - v0 for Möller–Trumbore;
//   refs:  (geomID, primID) in INPUT order, which is what a hit reports.
#pragma once

#include <cstddef>
#include "bvh/build_array.h"
#include "bvh/prim_info.h"
#include "core/vec.h"

namespace hprt {

struct TriangleVerts {
  Vec3f v0, v1, v2;
};
struct TriangleEdges {
  Vec3f v0, e1, e2;
};

struct LeafTriangles {
  BuildArray<TriangleVerts> verts;
  BuildArray<TriangleEdges> edges;
  BuildArray<PrimRef> refs;

  size_t size() const { return refs.size(); }
  // n uninitialised triangles: the caller writes every one.
  void allocate(size_t n) {
    verts = BuildArray<TriangleVerts>(n);
    edges = BuildArray<TriangleEdges>(n);
    refs = BuildArray<PrimRef>(n);
  }
  size_t memory_bytes() const {
    return verts.size() * sizeof(TriangleVerts) + edges.size() * sizeof(TriangleEdges) +
           refs.size() * sizeof(PrimRef);
  }
};

}  // namespace hprt
