// Triangle soup generator: unconnected small triangles with uniform random
// centres and orientations in the unit cube (no shared vertices).
#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "meshgen/generate_random.h"
#include "meshgen/mesh_generators.h"

namespace hprt {

TriangleMesh generate_soup(size_t tris, uint64_t seed) {
  const double size = 0.5 / std::cbrt(double(std::max<size_t>(tris, 1)));
  TriangleMesh mesh;
  mesh.name = "soup(" + std::to_string(tris) + ", seed " + std::to_string(seed) + ")";
  mesh.positions.resize(3 * tris);
  mesh.triangles.resize(tris);
  // Blocks of kGeneratorBlock triangles, each from its own seeded stream.
  const size_t blocks = (tris + kGeneratorBlock - 1) / kGeneratorBlock;
  tbb::parallel_for(size_t{0}, blocks, [&](size_t block) {
    GeneratorRng rng(stream_seed(seed, block));
    const size_t end = std::min(tris, (block + 1) * kGeneratorBlock);
    for (size_t t = block * kGeneratorBlock; t < end; ++t) {
      // Corners at 120° steps on a circle of random radius in a random plane,
      // so no triangle is degenerate; centre kept far enough inside the cube.
      const double r = size * rng.uniform(0.5, 1.0);
      const Vec3d c(rng.uniform(r, 1.0 - r), rng.uniform(r, 1.0 - r), rng.uniform(r, 1.0 - r));
      const Vec3d n = rng.unit_vector();
      const Vec3d e1 = perpendicular(n), e2 = cross(n, e1);
      const double phase = rng.uniform(0.0, 2.0 * GeneratorRng::kPi);
      const uint32_t base = uint32_t(3 * t);
      for (int k = 0; k < 3; ++k) {
        const double a = phase + 2.0 * GeneratorRng::kPi * k / 3.0;
        mesh.positions[base + k] = Vec3f(c + (e1 * std::cos(a) + e2 * std::sin(a)) * r);
      }
      mesh.triangles[t] = Vec3u{{base, base + 1, base + 2}};
    }
  });
  return mesh;
}

}  // namespace hprt
