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

// The scene's bounds, or the box [-1, 1]^3 for an empty scene.
inline AABB scene_box_or_unit(const Scene& scene) {
  AABB b = scene.bounds();
  if (b.empty()) b = AABB(Vec3f(-1.0f), Vec3f(1.0f));
  return b;
}

}  // namespace hprt
