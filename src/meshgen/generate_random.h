// Portable random numbers for the generators: std::mt19937_64 is fully
// specified by the standard, but std::uniform_real_distribution is not, so
// the mapping to [0,1) and to unit vectors is ours (same mesh on every libc++).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>

#include "core/splitmix64.h"
#include "core/vec.h"

namespace hprt {

class GeneratorRng {
 public:
  explicit GeneratorRng(uint64_t seed) : engine_(seed) {}

  // Uniform in [0, 1): the top 53 bits of one 64-bit draw.
  double uniform() { return double(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

  // Uniform direction on the unit sphere (Archimedes: z uniform, angle uniform).
  Vec3d unit_vector() {
    const double z = uniform(-1.0, 1.0);
    const double phi = uniform(0.0, 2.0 * kPi);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }

  static constexpr double kPi = 3.14159265358979323846;

 private:
  std::mt19937_64 engine_;
};

// Seed of the independent stream number `index` of a generator (splitmix64
// finaliser), so blocks of a mesh can be generated in parallel and the result
// does not depend on the thread count.
inline uint64_t stream_seed(uint64_t seed, uint64_t index) {
  return splitmix64_mix(seed + (index + 1) * kSplitMixGamma);
}

// Triangles per random stream in soup and slivers.
inline constexpr size_t kGeneratorBlock = 16384;

// Any unit vector perpendicular to the unit vector n.
inline Vec3d perpendicular(const Vec3d& n) {
  const Vec3d a = std::abs(n.x) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
  return normalize(cross(n, a));
}

}  // namespace hprt
