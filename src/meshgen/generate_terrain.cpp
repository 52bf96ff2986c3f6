// Height-field generators over [-1,1]² (xz plane, +y up): terrain from seeded
// value noise (hashed lattice values, smoothstep interpolation, 5 octaves of
// doubling frequency and halving amplitude), a flat plane on the same grid,
// and a terrain sheet of sliver cells.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/splitmix64.h"
#include "meshgen/mesh_generators.h"

namespace hprt {
namespace {

// Lattice value in [-1, 1) for integer point (ix, iz) of one octave.
double lattice(uint64_t seed, int octave, int64_t ix, int64_t iz) {
  uint64_t h = splitmix64(seed ^ (uint64_t(octave) << 56));
  h = splitmix64(h ^ uint64_t(ix));
  h = splitmix64(h ^ uint64_t(iz));
  return double(h >> 11) * 0x1.0p-52 - 1.0;
}

double value_noise(uint64_t seed, double x, double z) {
  constexpr int kOctaves = 5;
  constexpr double kHeight = 0.25;  // sum of the octave amplitudes
  double height = 0.0, amplitude = kHeight / (2.0 - std::ldexp(1.0, 1 - kOctaves));
  double freq = 2.0;  // lattice cells per unit length at octave 0
  for (int o = 0; o < kOctaves; ++o) {
    const double fx = x * freq, fz = z * freq;
    const double x0 = std::floor(fx), z0 = std::floor(fz);
    const double tx = fx - x0, tz = fz - z0;
    const double sx = tx * tx * (3 - 2 * tx), sz = tz * tz * (3 - 2 * tz);
    const int64_t ix = int64_t(x0), iz = int64_t(z0);
    const double a = lattice(seed, o, ix, iz), b = lattice(seed, o, ix + 1, iz);
    const double c = lattice(seed, o, ix, iz + 1), d = lattice(seed, o, ix + 1, iz + 1);
    height += amplitude * ((a + (b - a) * sx) * (1 - sz) + (c + (d - c) * sx) * sz);
    amplitude *= 0.5;
    freq *= 2.0;
  }
  return height;
}

// gx x gz cells over [-1,1]², each split into two triangles.
TriangleMesh height_field(size_t gx, size_t gz, bool noise, uint64_t seed) {
  const size_t row = gx + 1;
  TriangleMesh mesh;
  mesh.positions.resize(row * (gz + 1));
  mesh.triangles.resize(2 * gx * gz);
  tbb::parallel_for(size_t{0}, gz + 1, [&](size_t k) {
    const double z = -1.0 + 2.0 * double(k) / double(gz);
    for (size_t i = 0; i < row; ++i) {
      const double x = -1.0 + 2.0 * double(i) / double(gx);
      const double y = noise ? value_noise(seed, x, z) : 0.0;
      mesh.positions[k * row + i] = Vec3f(Vec3d(x, y, z));
    }
  });
  for (size_t k = 0; k < gz; ++k)
    for (size_t i = 0; i < gx; ++i) {
      const uint32_t a = uint32_t(k * row + i), b = a + 1;
      const uint32_t d = uint32_t(a + row), c = d + 1;
      // Counter-clockwise seen from +y.
      mesh.triangles[2 * (k * gx + i)] = Vec3u{{a, c, b}};
      mesh.triangles[2 * (k * gx + i) + 1] = Vec3u{{a, d, c}};
    }
  return mesh;
}

}  // namespace

int grid_segments(size_t tris) {
  int g = std::max(1, int(std::sqrt(double(tris) / 2.0)));
  while (2.0 * g * g < double(tris)) ++g;
  while (g > 1 && 2.0 * (g - 1) * (g - 1) >= double(tris)) --g;
  return g;
}

TriangleMesh generate_terrain(size_t tris, uint64_t seed) {
  const size_t g = size_t(grid_segments(tris));
  TriangleMesh mesh = height_field(g, g, true, seed);
  mesh.name =
      "terrain(" + std::to_string(mesh.triangle_count()) + ", seed " + std::to_string(seed) + ")";
  return mesh;
}

TriangleMesh generate_plane(size_t tris) {
  const size_t g = size_t(grid_segments(tris));
  TriangleMesh mesh = height_field(g, g, false, 0);
  mesh.name = "plane(" + std::to_string(mesh.triangle_count()) + ")";
  return mesh;
}

}  // namespace hprt

namespace hprt {

TriangleMesh generate_sliver_sheet(size_t tris, uint64_t seed) {
  // Cells kSliverAspect times longer in x than in z: gz = aspect * gx and
  // 2 * gx * gz >= tris.
  size_t gx = std::max<size_t>(1, size_t(std::sqrt(double(tris) / (2.0 * kSliverAspect))));
  while (2 * gx * gx * kSliverAspect < tris) ++gx;
  TriangleMesh mesh = height_field(gx, gx * kSliverAspect, true, seed);
  mesh.name =
      "sheet(" + std::to_string(mesh.triangle_count()) + ", seed " + std::to_string(seed) + ")";
  return mesh;
}

}  // namespace hprt
