// Points where camera rays meet the scene: the starting points of the
// secondary-ray workloads (shadow and reflection rays).
#pragma once

#include <cstddef>
#include <string_view>
#include <vector>

#include "backends/intersector.h"
#include "core/scene.h"
#include "core/splitmix64.h"
#include "core/vec.h"

namespace hprt {

// A primary hit: the surface point rebuilt from the barycentrics (more
// accurate than org + t dir), the unit geometric normal facing the incoming
// ray, and the incoming ray's direction.
struct SurfaceHit {
  Vec3f p;
  Vec3f n;
  Vec3f dir;
};

// n hits of primary rays (primary_rays' distribution) traced through
// `backend`, which must be built over `scene`; taken evenly over the image.
// Misses are replaced by rays through other pixels. Throws OptionError("kind",
// ...) naming `kind` when the camera sees too little of the scene, and
// std::invalid_argument without a backend.
std::vector<SurfaceHit> primary_surface_hits(const Scene& scene, size_t n, SplitMix64& rng,
                                             const Intersector* backend, std::string_view kind);

}  // namespace hprt
