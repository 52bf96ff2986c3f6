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

// Which test arrays a layout holds (and a refit rewrites): both, or only the
// one a triangle test reads (verts: watertight, edges: Möller–Trumbore; the
// backend keeps only its test's, a third less memory and flatten writes).
enum class TriangleArrays { kBoth, kVerts, kEdges };

struct LeafTriangles {
  BuildArray<TriangleVerts> verts;  // empty when not held
  BuildArray<TriangleEdges> edges;  // empty when not held
  BuildArray<PrimRef> refs;

  size_t size() const { return refs.size(); }
  // n triangles, contents unspecified (arrays of that size already held are
  // kept, BuildArray::reset): the caller writes every one of the arrays held.
  void allocate(size_t n, TriangleArrays which = TriangleArrays::kBoth) {
    verts.reset(which != TriangleArrays::kEdges ? n : 0);
    edges.reset(which != TriangleArrays::kVerts ? n : 0);
    refs.reset(n);
  }
  // Whether the arrays `which` names are held for every triangle.
  bool holds(TriangleArrays which) const {
    return (which == TriangleArrays::kEdges || verts.size() == refs.size()) &&
           (which == TriangleArrays::kVerts || edges.size() == refs.size());
  }
  size_t memory_bytes() const {
    return verts.size() * sizeof(TriangleVerts) + edges.size() * sizeof(TriangleEdges) +
           refs.size() * sizeof(PrimRef);
  }
};

}  // namespace hprt
