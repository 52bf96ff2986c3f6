// The catalogue of query point sets, by kind name, for `hprt points`, `hprt
// validate query` and the benchmarks (the point queries' counterpart of
// ray_sets.h):
//   random: uniform in the scene's box enlarged by 10% on each side;
//   near:   on the triangles (a random point of a random triangle, rounded
//           to float: within float rounding of the surface, on either side
//           or exactly on it), where inside/outside is hardest to decide;
//   hard:   in turn a random point, one on a plane through a vertex (one of
//           its coordinates), a vertex itself, one ulp beside a vertex, and
//           one on the axis-parallel line through a vertex.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/scene.h"
#include "core/vec.h"

namespace hprt {

// The most points a point set may hold (1e9 points: 12 GB of .points).
inline constexpr size_t kMaxPointSetSize = 1'000'000'000;

enum class PointKind { kRandom = 0, kNear = 1, kHard = 2 };

std::string_view to_string(PointKind kind);
// Throws OptionError("kind", ...) naming the valid kinds.
PointKind parse_point_kind(std::string_view name);
std::vector<std::string> point_kind_names();

// n points of `kind`, the same for the same seed and scene. Throws
// InputError when the scene has no valid triangle.
// `scene_name` (its file) names the scene in the InputError of a scene with
// no valid triangle.
std::vector<Vec3f> make_points(const Scene& scene, PointKind kind, size_t n, uint64_t seed,
                               const std::string& scene_name = "scene");

}  // namespace hprt
