// Mesh placement from a scene file (see scene_transform.h).
#include "io/scene/scene_transform.h"

#include <tbb/parallel_for.h>

#include <array>
#include <cmath>

namespace hprt {
namespace {

using Mat3 = std::array<Vec3d, 3>;  // rows

Vec3d mul(const Mat3& m, const Vec3d& v) { return {dot(m[0], v), dot(m[1], v), dot(m[2], v)}; }

Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
  return r;
}

Mat3 rotation(int axis, double deg) {
  const double rad = deg * (3.14159265358979323846 / 180.0);
  const double c = std::cos(rad), s = std::sin(rad);
  switch (axis) {
    case 0:
      return {Vec3d(1, 0, 0), Vec3d(0, c, -s), Vec3d(0, s, c)};
    case 1:
      return {Vec3d(c, 0, s), Vec3d(0, 1, 0), Vec3d(-s, 0, c)};
    default:
      return {Vec3d(c, -s, 0), Vec3d(s, c, 0), Vec3d(0, 0, 1)};
  }
}

}  // namespace

void apply_transform(TriangleMesh& mesh, const MeshTransform& t) {
  if (t.identity()) return;
  const Mat3 r = mul(rotation(2, t.rotate_deg.z),
                     mul(rotation(1, t.rotate_deg.y), rotation(0, t.rotate_deg.x)));
  const Vec3d s(t.scale), tr(t.translate);
  tbb::parallel_for(size_t{0}, mesh.positions.size(), [&](size_t i) {
    mesh.positions[i] = Vec3f(mul(r, Vec3d(mesh.positions[i]) * s) + tr);
  });
  tbb::parallel_for(size_t{0}, mesh.normals.size(), [&](size_t i) {
    const Vec3d n = mul(r, Vec3d(mesh.normals[i]) / s);
    const double len = length(n);
    mesh.normals[i] = len > 0.0 ? Vec3f(n / len) : mesh.normals[i];
  });
}

}  // namespace hprt
