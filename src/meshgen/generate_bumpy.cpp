// Bumpy sphere: the sphere generator's mesh with every vertex moved along its
// direction by a sum of seeded plane waves over the sphere, so the surface is
// closed and smooth like a scan but curved at many scales (a stand-in for
// scanned models at any size). Waves of higher frequency get smaller
// amplitudes; the radius stays within 1 ± 0.2.
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>

#include "meshgen/generate_random.h"
#include "meshgen/mesh_generators.h"

namespace hprt {
namespace {

struct Wave {
  Vec3d direction;
  double frequency, amplitude, phase;
};

constexpr int kWaves = 24;

std::array<Wave, kWaves> make_waves(uint64_t seed) {
  GeneratorRng rng(seed);
  std::array<Wave, kWaves> waves;
  double total = 0.0;
  for (Wave& w : waves) {
    w.direction = rng.unit_vector();
    w.frequency = rng.uniform(2.0, 40.0);
    w.amplitude = 1.0 / w.frequency;
    w.phase = rng.uniform(0.0, 2.0 * GeneratorRng::kPi);
    total += w.amplitude;
  }
  for (Wave& w : waves) w.amplitude *= 0.2 / total;  // |sum| <= 0.2
  return waves;
}

}  // namespace

TriangleMesh generate_bumpy_sphere(size_t tris, uint64_t seed) {
  TriangleMesh mesh = generate_sphere(tris);
  mesh.name = "bumpy";
  mesh.normals.clear();
  const std::array<Wave, kWaves> waves = make_waves(seed);
  tbb::parallel_for(size_t(0), mesh.positions.size(), [&](size_t i) {
    const Vec3d p = normalize(Vec3d(mesh.positions[i]));
    double r = 1.0;
    for (const Wave& w : waves)
      r += w.amplitude * std::sin(w.frequency * dot(p, w.direction) + w.phase);
    mesh.positions[i] = Vec3f(p * r);
  });
  return mesh;
}

}  // namespace hprt
