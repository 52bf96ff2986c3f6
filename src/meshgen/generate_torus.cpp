// Torus generator: a major × minor grid of quads on a torus around the y axis,
// wrapping in both directions so the surface is closed and vertices shared.
#include <algorithm>
#include <cmath>

#include "meshgen/mesh_generators.h"

namespace hprt {

TriangleMesh generate_torus(size_t tris) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kMajor = 1.0, kMinor = 0.35;
  const size_t minor = std::max<size_t>(3, size_t(std::llround(std::sqrt(double(tris) / 6.0))));
  const size_t major = std::max<size_t>(3, (tris + 2 * minor - 1) / (2 * minor));

  TriangleMesh mesh;
  mesh.name = "torus(" + std::to_string(2 * major * minor) + ")";
  mesh.positions.reserve(major * minor + 1);
  mesh.triangles.reserve(2 * major * minor);
  for (size_t i = 0; i < major; ++i) {
    const double u = 2.0 * kPi * double(i) / double(major);
    for (size_t j = 0; j < minor; ++j) {
      const double v = 2.0 * kPi * double(j) / double(minor);
      const double r = kMajor + kMinor * std::cos(v);
      mesh.positions.push_back(
          Vec3f(Vec3d(r * std::cos(u), kMinor * std::sin(v), -r * std::sin(u))));
    }
  }
  auto id = [&](size_t i, size_t j) { return uint32_t((i % major) * minor + (j % minor)); };
  for (size_t i = 0; i < major; ++i)
    for (size_t j = 0; j < minor; ++j) {
      const uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      mesh.triangles.push_back(Vec3u{{a, b, c}});
      mesh.triangles.push_back(Vec3u{{a, c, d}});
    }
  return mesh;
}

}  // namespace hprt
