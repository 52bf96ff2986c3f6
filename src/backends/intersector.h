// The one interface both backends implement. Batch calls only, so the virtual
// dispatch happens once per batch and never per ray. Semantics are Embree 3's:
// closest hit in [tnear, tfar], double-sided triangles, primID in input order,
// geomID = mesh index, rays with NaN or zero direction miss. Rays Embree
// calls invalid miss too: an org/dir component that is non-finite or above
// 1.844e18 (Embree's FLT_LARGE), tnear < 0, or not tnear <= tfar (NaN).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bvh/input/build_options.h"
#include "core/hit.h"
#include "core/hit_columns.h"
#include "core/hit_lists.h"
#include "core/point_query.h"
#include "core/ray.h"
#include "core/ray_input.h"
#include "core/scene.h"
#include "core/tree_stats.h"

namespace hprt {

// kAuto (the default) chooses per frame between refit, Morton rebuild and
// SAH rebuild from measured times (backends/auto_update_policy.h); kAdaptive
// rebuilds with the configured builder past adaptive_factor (update_policy.h).
enum class UpdateStrategy { kRebuild, kRefit, kAdaptive, kAuto };

struct BackendOptions {
  std::string backend = "bvh";  // bvh | embree | plugin:PATH[:OPTIONS] (backend_spec.h)
  int threads = 0;              // 0 = all hardware threads
  // bvh backend
  BuildOptions build;
  TriangleTestKind triangle_test = TriangleTestKind::kWatertight;
  BvhLayout layout = BvhLayout::kBvh8;
  // embree backend
  std::string embree_quality = "medium";  // low | medium | high | refit
  bool embree_robust = false;
  // deformable scenes
  UpdateStrategy update = UpdateStrategy::kAuto;
  // adaptive (and auto until a query was timed): rebuild when the refitted
  // SAH cost exceeds this factor x the cost at the last rebuild
  float adaptive_factor = 1.3f;
  // An update()'s rebuild reports sah_cost, nodes and triangle counts; the
  // rest of TreeStats (leaves, depth, leaf sizes, tree_hash: a pass over the
  // whole tree that only reports) only with this set. build() reports all.
  bool full_stats_on_update = false;
};

struct BuildInfo {
  std::string name;       // e.g. "bvh/parallel/watertight" or "embree/medium"
  double build_ms = 0.0;  // last build() or update()
  size_t memory_bytes = 0;
  bool has_tree_stats = false;
  TreeStats stats;
  bool rebuilt = true;  // update(): whether the last update rebuilt (vs refit)
  // The builder of this build(), or of update()'s rebuild ("parallel",
  // "morton", ...); empty after a refit or where the backend does not say.
  std::string rebuilt_with;
  // Plugins: answers so far that failed the checks of core/hit_check.h.
  uint64_t malformed_answers = 0;
};

class Intersector {
 public:
  virtual ~Intersector() = default;
  virtual void build(const Scene& scene) = 0;
  virtual void update(const Scene& scene) = 0;
  virtual void intersect(std::span<const Ray> rays, std::span<Hit> hits) const = 0;
  // occluded[i] = 1 when rays[i] hits something in (tnear, tfar]; the rays
  // are records or six floats each (core/ray_input.h).
  virtual void occluded(const RayInput& rays, std::span<uint8_t> occluded) const = 0;
  // Closest hits as intersect() answers them, written as columns
  // (core/hit_columns.h) with each hit triangle's unit normal
  // (core/triangle_normal.h); `scene` is the one built over. The rays are
  // records or six floats each (core/ray_input.h). The default traces a
  // chunk at a time into records, then copies them and computes each normal
  // from the scene's vertices; the bvh backend reads the rays a block at a
  // time and writes the columns as it traces.
  virtual void intersect_columns(const Scene& scene, const RayInput& rays,
                                 const HitColumns& out) const;
  // Crossings: counts[i] = how many triangles rays[i] hits in (tnear, tfar].
  // The bvh backend's watertight test counts every crossing of a surface
  // exactly once (its fill rule); Embree reports every triangle its test
  // hits, so a ray through a shared edge may count twice or not at all.
  // Backends that cannot answer throw OptionError("query", ...).
  virtual void count(const RayInput& rays, std::span<uint32_t> counts) const;
  // Every hit of each ray in (tnear, tfar] in order of t, the nearest
  // max_per_ray kept (core/hit_lists.h).
  virtual void intersect_all(const RayInput& rays, uint32_t max_per_ray, HitLists& out) const;
  // Point queries (core/point_query.h), out.size() >= points.size().
  // locate: inside, outside or on the surface of the scene's closed meshes
  // (the bvh backend decides exactly; Embree by the parity of its crossing
  // count along the same ray, on the surface where its closest-point query
  // finds distance 0). closest: the nearest surface point within
  // max_distance (inclusive; +inf for no bound).
  virtual void locate(std::span<const Vec3f> points, std::span<PointLocation> out) const;
  virtual void closest(std::span<const Vec3f> points, float max_distance,
                       std::span<ClosestPoint> out) const;
  virtual BuildInfo info() const = 0;
};

// `backend`: bvh, embree or plugin:PATH[:OPTIONS] (backends/backend_spec.h).
// Throws OptionError("backend", ...) when it is unknown, InputError naming
// the plugin file when a plugin cannot be loaded or created.
std::unique_ptr<Intersector> make_intersector(std::string_view backend,
                                              const BackendOptions& options);

}  // namespace hprt
