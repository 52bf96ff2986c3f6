// The catalogue of ray sets, by kind name, for `hprt rays`, `hprt validate
// rays`, benchmarks and tests: the renderer's workloads (src/workload:
// primary, shadow, reflection, diffuse, random) and the hard numerical cases
// (hard_rays.h: vertex/edge probes, grazing, axis-parallel, NaN).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "backends/intersector.h"
#include "core/ray.h"
#include "core/scene.h"

namespace hprt {

// The values seed each kind's stream (make_rays): a kind keeps its number,
// so a seed gives the same rays in every version.
enum class RayKind {
  kPrimary = 0,      // camera rays through jittered positions, scanline order
  kShadow = 1,       // from primary hits toward scene.lights[0]
  kReflection = 2,   // mirror direction at primary hits
  kDiffuse = 9,      // cosine-weighted bounce directions at primary hits
  kRandom = 3,       // origins in the enlarged scene box, directions uniform on the sphere
  kVertexProbe = 4,  // from a closed mesh's centroid exactly at one of its vertices
  kEdgeProbe = 5,    // from a closed mesh's centroid at an edge midpoint
  kGrazing = 6,      // nearly in a triangle's plane, through its centroid
  kAxis = 7,         // exactly axis-parallel (other components ±0), through vertices
  kNan = 8,          // invalid rays that must miss (NaN, inf, zero direction, empty interval)
};

std::string_view to_string(RayKind kind);
// Whether make_rays needs a built backend for `kind` (the secondary rays
// start at primary hits).
bool ray_kind_needs_backend(RayKind kind);
// Throws OptionError("kind", ...) naming the valid kinds.
RayKind parse_ray_kind(std::string_view name);
std::vector<std::string> ray_kind_names();

// The most rays a ray set may hold (1e9 rays: 32 GB of .rays records); a
// count option above it is an error before anything is allocated.
inline constexpr size_t kMaxRaySetSize = 1'000'000'000;
// Throws OptionError(key, ...) when n > kMaxRaySetSize.
void check_ray_count(const std::string& key, size_t n);

// n rays of `kind`, the same for the same seed. Shadow, reflection and diffuse rays
// trace primary rays through `backend`, which must be built over `scene`;
// other kinds ignore it. Throws InputError when the scene cannot give this
// kind (no triangles, no light, no closed mesh for probes, too few hits).
std::vector<Ray> make_rays(const Scene& scene, RayKind kind, size_t n, uint64_t seed,
                           const Intersector* backend = nullptr);

}  // namespace hprt
