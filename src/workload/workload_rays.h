// The rays a renderer traces, as sets for benchmarks, tests and validation:
// coherent camera rays, shadow, mirror and diffuse bounce rays from their
// hits, and incoherent random rays. Each draws from the caller's splitmix64 stream, so
// a set is the same for the same stream state on any platform.
#pragma once

#include <cstddef>
#include <vector>

#include "backends/intersector.h"
#include "core/ray.h"
#include "core/scene.h"
#include "core/splitmix64.h"

namespace hprt {

// Scanline-ordered, stratified-jittered camera rays: ray i lands in pixel
// floor((i + u) * W * H / n), so the set is coherent like a render's.
std::vector<Ray> primary_rays(const Scene& scene, size_t n, SplitMix64& rng);

// From primary hits (primary_surface_hits, through `backend`) toward
// scene.lights[0]: a point light sits at t = 1 (tfar just short of it), a
// directional light at infinity. Throws OptionError("kind", ...) without a
// light.
std::vector<Ray> shadow_rays(const Scene& scene, size_t n, SplitMix64& rng,
                             const Intersector* backend);

// The mirror direction at primary hits.
std::vector<Ray> reflection_rays(const Scene& scene, size_t n, SplitMix64& rng,
                                 const Intersector* backend);

// Cosine-weighted directions over the hemisphere of the normal at primary
// hits (the side the camera sees): the bounce rays of a path tracer's diffuse
// surfaces, the standard incoherent secondary rays. Unit directions.
std::vector<Ray> diffuse_rays(const Scene& scene, size_t n, SplitMix64& rng,
                              const Intersector* backend);

// Origins uniform in the scene box enlarged by 10%, directions uniform on the
// sphere.
std::vector<Ray> random_rays(const Scene& scene, size_t n, SplitMix64& rng);

}  // namespace hprt
