// Triangles reordered into leaf order (a leaf covers [first, first + count)),
// with the data each ray/triangle test reads precomputed, one array per test
// so a leaf's triangles are contiguous for the test in use (a 4-triangle leaf
// is 144 bytes: 2-3 cache lines, instead of 3-6 with one array per vertex):
//   verts: the raw v0, v1, v2 for the watertight test (v0 + e1 would not
//          reproduce v1 exactly, and watertightness needs the exact vertices),
//          block by block as structure of arrays: the triangles of a block
//          (a leaf of the build tree) [first, first + count) hold the 9 *
//          count floats from 9 * first on, as 9 rows (v0.x, v0.y, v0.z,
//          v1.x, ..., v2.z) of `count` floats, so one load brings a
//          coordinate of every triangle of a leaf (Embree's Triangle4 blocks
//          do the same in fixed groups of 4);
//   edges: v0, e1 = v1 - v0, e2 = v2 - v0 for Möller–Trumbore;
//   refs:  (geomID, primID) in INPUT order, which is what a hit reports.
#pragma once

#include <cstddef>
#include <cstdint>

#include "bvh/input/prim_info.h"
#include "bvh/memory/build_array.h"
#include "core/vec.h"

namespace hprt {

struct TriangleVerts {
  Vec3f v0, v1, v2;
};

// A traversal leaf: its triangles [first, first + count), which lie in the
// verts block [block_first, block_first + block_count) (the leaf itself, or
// the build-tree leaf it is a part of in a wide layout).
struct LeafRange {
  uint32_t first = 0, count = 0;
  uint32_t block_first = 0, block_count = 0;

  static constexpr LeafRange whole(uint32_t first, uint32_t count) {
    return {first, count, first, count};
  }
};
struct TriangleEdges {
  Vec3f v0, e1, e2;
};

// Which test arrays a layout holds (and a refit rewrites): both, or only the
// one a triangle test reads (verts: watertight, edges: Möller–Trumbore; the
// backend keeps only its test's, a third less memory and flatten writes).
enum class TriangleArrays { kBoth, kVerts, kEdges };

struct LeafTriangles {
  BuildArray<float> verts;          // 9 per triangle, in blocks (above); empty when not held
  BuildArray<TriangleEdges> edges;  // empty when not held
  BuildArray<PrimRef> refs;

  size_t size() const { return refs.size(); }
  // n triangles, contents unspecified (arrays of that size already held are
  // kept, BuildArray::reset): the caller writes every one of the arrays held.
  void allocate(size_t n, TriangleArrays which = TriangleArrays::kBoth) {
    verts.reset(which != TriangleArrays::kEdges ? 9 * n : 0);
    edges.reset(which != TriangleArrays::kVerts ? n : 0);
    refs.reset(n);
  }
  // Whether the arrays `which` names are held for every triangle.
  bool holds(TriangleArrays which) const {
    return (which == TriangleArrays::kEdges || verts.size() == 9 * refs.size()) &&
           (which == TriangleArrays::kVerts || edges.size() == refs.size());
  }
  size_t memory_bytes() const {
    return verts.size() * sizeof(float) + edges.size() * sizeof(TriangleEdges) +
           refs.size() * sizeof(PrimRef);
  }

  // Row r (3 * vertex + axis) of the verts block at `block_first` holding
  // `block_count` triangles: one coordinate of each, in leaf order.
  const float* vert_row(uint32_t block_first, uint32_t block_count, int r) const {
    return verts.data() + 9 * size_t(block_first) + size_t(r) * block_count;
  }
  // Vertices of triangle i of `leaf`'s block.
  TriangleVerts triangle(const LeafRange& leaf, uint32_t i) const {
    const float* p = vert_row(leaf.block_first, leaf.block_count, 0) + (i - leaf.block_first);
    const size_t s = leaf.block_count;
    return {{p[0], p[s], p[2 * s]}, {p[3 * s], p[4 * s], p[5 * s]}, {p[6 * s], p[7 * s], p[8 * s]}};
  }
  // Writes triangle i of `leaf`'s block (gather, refit).
  void set_triangle(const LeafRange& leaf, uint32_t i, const Vec3f& a, const Vec3f& b,
                    const Vec3f& c) {
    float* p = verts.data() + 9 * size_t(leaf.block_first) + (i - leaf.block_first);
    const size_t s = leaf.block_count;
    const float v[9] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
    for (int r = 0; r < 9; ++r) p[r * s] = v[r];
  }
};

}  // namespace hprt
