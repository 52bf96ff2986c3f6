// Numerically hard ray sets, where float ray/triangle tests go wrong: rays at
// a closed mesh's vertices and edges, grazing rays, exactly axis-parallel
// rays, and invalid rays that must miss. Each draws from the caller's
// splitmix64 stream. Throws OptionError("kind", ...) when the scene cannot
// give the kind (no triangles; no closed mesh for probes).
#pragma once

#include <cstddef>
#include <vector>

#include "core/ray.h"
#include "core/scene.h"
#include "core/splitmix64.h"

namespace hprt {

// From a closed mesh's centroid (every edge shared by two triangles) exactly
// at one of its vertices (`at_vertex`) or edge midpoints; unnormalised, the
// target sits at t = 1.
std::vector<Ray> probe_rays(const Scene& scene, size_t n, SplitMix64& rng, bool at_vertex);

// Nearly in a triangle's plane (normal component 1e-4 .. 1e-7 of the unit
// direction), through its centroid.
std::vector<Ray> grazing_rays(const Scene& scene, size_t n, SplitMix64& rng);

// Exactly axis-parallel (other components +0 or -0), through mesh vertices;
// half start on the scene box's plane, half outside it.
std::vector<Ray> axis_rays(const Scene& scene, size_t n, SplitMix64& rng);

// Rays toward the scene's centre, each broken in one of ten ways (NaN, inf,
// zero direction, empty or NaN interval, negative tnear, a component above
// Embree's limit); every one must miss (intersector.h: invalid rays miss).
std::vector<Ray> nan_rays(const Scene& scene, size_t n, SplitMix64& rng);

}  // namespace hprt
