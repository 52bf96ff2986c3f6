// Whitted ray tracing (the report's Algorithm 6): ambient + Lambert/Blinn-Phong
// per light with hard shadows + recursive mirror reflection, traced wavefront
// style per image tile so every backend answers the same ray batches.
#pragma once

#include <cstdint>

#include "backends/intersector.h"
#include "core/camera.h"
#include "core/scene.h"
#include "render/framebuffer.h"

namespace hprt {

class Progress;

// A path stops once the product of reflectivities along it falls below this:
// its contribution is then under a thousandth of the first surface's.
inline constexpr float kMinPathWeight = 1e-3f;

struct RenderOptions {
  int tile_size = 32;            // pixels per tile side
  Progress* progress = nullptr;  // advanced by one per finished tile
};

struct RenderStats {
  uint64_t primary_rays = 0;
  uint64_t shadow_rays = 0;
  uint64_t reflection_rays = 0;
  uint64_t rays() const { return primary_rays + shadow_rays + reflection_rays; }
};

// Renders `scene` through `camera` with `intersector`, already built over
// `scene`. Parallel over tiles in the caller's task arena (run_with_threads);
// the image does not depend on the thread count. Lights: scene.lights as
// given; an empty list means ambient only (load_scene gives a file without
// "lights" a head light, and "lights": [] means none).
// Depth: the primary hit is depth 0; reflection rays are traced up to depth
// scene.max_depth (0 = no reflections). Triangles are double-sided: the
// normal is turned toward the incoming ray.
Framebuffer render_whitted(const Scene& scene, const Camera& camera, const Intersector& intersector,
                           RenderStats* stats = nullptr, const RenderOptions& options = {});

}  // namespace hprt
