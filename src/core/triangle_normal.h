// A triangle's unit geometric normal, the one every normal hprt reports is
// (Intersector::intersect_columns, api::Scene::normals, and through them
// RaycastingScene's primitive_normals):
// (b - a) x (c - a) computed in double and normalised, then rounded to
// float, so every backend and layout gives the same bits; zero for a
// degenerate triangle.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/triangle_mesh.h"

namespace hprt {

inline void unit_normal(const float* a, const float* b, const float* c, float* n) {
  const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
  const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
  const double x = e1[1] * e2[2] - e1[2] * e2[1];
  const double y = e1[2] * e2[0] - e1[0] * e2[2];
  const double z = e1[0] * e2[1] - e1[1] * e2[0];
  const double len = std::sqrt(x * x + y * y + z * z);
  n[0] = n[1] = n[2] = 0.0f;
  if (len > 0.0) n[0] = float(x / len), n[1] = float(y / len), n[2] = float(z / len);
}

// The unit normal of triangle `prim` of `mesh`.
inline void triangle_normal(const TriangleMesh& mesh, uint32_t prim, float* n) {
  const Vec3u& t = mesh.triangles[prim];
  unit_normal(&mesh.positions[t[0]].x, &mesh.positions[t[1]].x, &mesh.positions[t[2]].x, n);
}

}  // namespace hprt
