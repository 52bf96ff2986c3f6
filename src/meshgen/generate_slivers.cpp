// Sliver generator: long thin triangles (length 0.05..0.3, width length/1000)
// in uniform random directions inside the unit cube; the worst case for
// bounding boxes, since each one's box is mostly empty.
#include <tbb/parallel_for.h>

#include <algorithm>

#include "meshgen/generate_random.h"
#include "meshgen/mesh_generators.h"

namespace hprt {

TriangleMesh generate_slivers(size_t tris, uint64_t seed) {
  constexpr double kAspect = 1000.0;
  TriangleMesh mesh;
  mesh.name = "slivers(" + std::to_string(tris) + ", seed " + std::to_string(seed) + ")";
  mesh.positions.resize(3 * tris);
  mesh.triangles.resize(tris);
  // Blocks of kGeneratorBlock triangles, each from its own seeded stream.
  const size_t blocks = (tris + kGeneratorBlock - 1) / kGeneratorBlock;
  tbb::parallel_for(size_t{0}, blocks, [&](size_t block) {
    GeneratorRng rng(stream_seed(seed, block));
    const size_t end = std::min(tris, (block + 1) * kGeneratorBlock);
    for (size_t t = block * kGeneratorBlock; t < end; ++t) {
      const double len = rng.uniform(0.05, 0.3);
      const double h = 0.5 * len;
      const Vec3d c(rng.uniform(h, 1.0 - h), rng.uniform(h, 1.0 - h), rng.uniform(h, 1.0 - h));
      const Vec3d d = rng.unit_vector();
      const Vec3d p = perpendicular(d);
      const Vec3d q = cross(d, p);
      const double phase = rng.uniform(0.0, 2.0 * GeneratorRng::kPi);
      const Vec3d w = p * std::cos(phase) + q * std::sin(phase);  // random width direction
      const uint32_t base = uint32_t(3 * t);
      mesh.positions[base] = Vec3f(c - d * h);
      mesh.positions[base + 1] = Vec3f(c + d * h);
      mesh.positions[base + 2] = Vec3f(c + w * (len / kAspect));
      mesh.triangles[t] = Vec3u{{base, base + 1, base + 2}};
    }
  });
  return mesh;
}

}  // namespace hprt
