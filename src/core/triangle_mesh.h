// An indexed triangle mesh in input order: triangle i of `triangles` is the
// primID Embree and the BVH report. Optional per-vertex normals.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/aabb.h"
#include "core/material.h"
#include "core/shared_array.h"
#include "core/vec.h"

namespace hprt {

// Whether triangle (a, b, c) has a nonzero normal, (b - a) x (c - a), decided
// exactly: the products of the float edge components are exact in double, so
// each component is zero exactly when its two products are equal, whether or
// not the compiler fuses the subtraction into an FMA. (In float the answer
// depended on that: prim info and refit, compiled apart, disagreed on nearly
// degenerate triangles.)
inline bool nonzero_area(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f e1 = b - a, e2 = c - a;
  const double x = double(e1.y) * double(e2.z) - double(e1.z) * double(e2.y);
  const double y = double(e1.z) * double(e2.x) - double(e1.x) * double(e2.z);
  const double z = double(e1.x) * double(e2.y) - double(e1.y) * double(e2.x);
  return x != 0.0 || y != 0.0 || z != 0.0;
}

struct TriangleMesh {
  std::string name;              // file path or generator description, for messages
  SharedArray<Vec3f> positions;  // see pad_for_embree(); may view a caller's array (shared_array.h)
  SharedArray<Vec3u> triangles;
  std::vector<Vec3f> normals;  // empty, or one per position
  Material material;

  size_t triangle_count() const { return triangles.size(); }
  size_t vertex_count() const { return positions.size(); }

  // Embree reads vertex buffers with 16-byte loads, so a shared float3 buffer
  // needs 4 readable bytes past the last vertex (Embree 3 API docs,
  // rtcSetSharedGeometryBuffer). Reserving one spare element provides them.
  // A view of a caller's array stays one (the embree backend then copies it).
  void pad_for_embree() {
    if (positions.is_view()) return;
    if (positions.capacity() < positions.size() + 1) positions.reserve(positions.size() + 1);
  }
  bool padded_for_embree() const { return positions.capacity() >= positions.size() + 1; }

  AABB bounds() const {
    AABB b;
    for (const Vec3f& p : positions)
      if (is_finite(p)) b.extend(p);
    return b;
  }

  // A triangle that can never be hit: an index out of range, a non-finite
  // vertex, or zero area (repeated or collinear vertices).
  bool triangle_valid(size_t i) const {
    const Vec3u& t = triangles[i];
    const size_t n = positions.size();
    if (t[0] >= n || t[1] >= n || t[2] >= n) return false;
    const Vec3f& a = positions[t[0]];
    const Vec3f& b = positions[t[1]];
    const Vec3f& c = positions[t[2]];
    if (!is_finite(a) || !is_finite(b) || !is_finite(c)) return false;
    return nonzero_area(a, b, c);
  }
};

}  // namespace hprt
