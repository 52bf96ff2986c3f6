// Sampling shared by the ray workloads and the hard ray sets: directions from
// a splitmix64 stream (no std:: distributions, whose results are
// library-defined, so a set is bit-identical for a seed on any platform) and
// the box rays are spread over.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/aabb.h"
#include "core/scene.h"
#include "core/splitmix64.h"
#include "core/vec.h"

namespace hprt {

// Uniform on the unit sphere.
inline Vec3f uniform_sphere(SplitMix64& rng) {
  const float z = 1.0f - 2.0f * rng.uniform();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * std::numbers::pi_v<float> * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Cosine-weighted on the hemisphere around the unit vector n (Malley: a
// uniform point of the unit disk lifted onto the hemisphere), in the
// orthonormal basis of Duff et al., "Building an Orthonormal Basis,
// Revisited" (JCGT 2017). Unit length.
inline Vec3f cosine_hemisphere(const Vec3f& n, SplitMix64& rng) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  const Vec3f t(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  const Vec3f bt(b, sign + n.y * n.y * a, -n.y);
  const float u1 = rng.uniform(), u2 = rng.uniform();
  const float r = std::sqrt(u1);
  const float phi = 2.0f * std::numbers::pi_v<float> * u2;
  return normalize(t * (r * std::cos(phi)) + bt * (r * std::sin(phi)) +
                   n * std::sqrt(std::max(0.0f, 1.0f - u1)));
}

// The scene's bounds, or the box [-1, 1]^3 for an empty scene.
inline AABB scene_box_or_unit(const Scene& scene) {
  AABB b = scene.bounds();
  if (b.empty()) b = AABB(Vec3f(-1.0f), Vec3f(1.0f));
  return b;
}

}  // namespace hprt
