// Open3D's RaycastingScene (open3d.t.geometry.RaycastingScene) over hprt's
// public API: the semantics the Python module's `hprt.RaycastingScene`
// exposes, on plain arrays, so that the bindings only convert numpy arrays.
// Rays are Open3D's 6 floats [ox, oy, oz, dx, dy, dz] with the interval
// (0, inf) (test_occlusions: (tnear, tfar]); ids are uint32 with
// kInvalidId on a miss. The backend is built on the first query after a
// change, as Open3D builds its scene.
#pragma once

#include <hprt/hprt.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <span>
#include <string>
#include <vector>

#include "raycasting/face_normals.h"

namespace hprt::raycasting {

// Where cast_rays writes, n rays each: t (inf on a miss), geometry and
// primitive ids, u, v (2 per ray) and the unit geometric normal (3 per ray,
// zero on a miss).
struct CastOutput {
  float* t_hit;
  uint32_t* geometry_ids;
  uint32_t* primitive_ids;
  float* primitive_uvs;
  float* primitive_normals;
};

// compute_closest_points writes, n points each: the closest point (3 per
// point), geometry and primitive ids, u, v (2 per point) and the triangle's
// unit normal (3 per point); an empty scene gives inf points, invalid ids,
// zero uvs and normals.
struct ClosestOutput {
  float* points;
  uint32_t* geometry_ids;
  uint32_t* primitive_ids;
  float* primitive_uvs;
  float* primitive_normals;
};

// list_intersections' result: ray i's hits are [ray_splits[i],
// ray_splits[i + 1]) of the other arrays, nearest first (uvs: 2 per hit).
struct IntersectionLists {
  std::vector<uint32_t> ray_splits;  // uint32, as Open3D's
  std::vector<uint32_t> ray_ids, geometry_ids, primitive_ids;
  std::vector<float> t_hit, primitive_uvs;
};

struct SceneInfo {
  std::string backend;  // configuration name
  double build_ms = 0.0;
  size_t memory_bytes = 0;   // the backend's structure
  size_t normals_bytes = 0;  // FaceNormals, once compute_closest_points made them
  size_t meshes = 0, triangles = 0;
  uint64_t malformed_answers = 0;
};

class RaycastingScene {
 public:
  // backend and options as hprt::api::Backend takes them; nthreads as
  // Open3D's (0 = every hardware thread). Throws api::Error.
  RaycastingScene(int nthreads, const std::string& backend, const api::Options& options);

  // The arrays are shared when `shared` (the caller keeps them alive and
  // unchanged), else copied (the Python module copies, as Open3D does).
  // Returns the geometry id.
  uint32_t add_triangles(std::span<const float> vertices, std::span<const uint32_t> indices,
                         bool shared);
  uint32_t add_triangles(const std::string& path);
  // Moves geometry `id`'s vertices (same count); the next query updates the
  // backend (refit or rebuild per its update option). A geometry added
  // shared shares `vertices` (kept alive by the caller), else copies them.
  void update_triangles(uint32_t id, std::span<const float> vertices, bool shared);

  // rays: 6 floats per ray. nthreads > 0 runs the call in that many threads
  // when the scene was made with nthreads 0 (else the scene's count holds);
  // 0 or less, as in Open3D: every hardware thread (or the scene's count).
  // Above api::kMaxThreads: api::Error.
  void cast_rays(std::span<const float> rays, const CastOutput& out, int nthreads);
  // tnear < 0 or not tnear <= tfar (NaN too): std::invalid_argument.
  void test_occlusions(std::span<const float> rays, float tnear, float tfar, uint8_t* occluded,
                       int nthreads);
  // Surface crossings along each ray in (0, inf), each counted once by the
  // bvh backend (api::Backend::count); Open3D's int32 per ray.
  void count_intersections(std::span<const float> rays, int32_t* counts, int nthreads);
  // Every crossing along each ray, nearest first.
  IntersectionLists list_intersections(std::span<const float> rays, int nthreads);
  // Point queries, 3 floats per point (api::Backend::closest and inside).
  // nsamples: Open3D's vote count, odd and >= 1 (else api::Error); the
  // answer is exact with one ray, so it changes nothing. Points exactly on
  // the surface have signed distance 0 and count as occupied.
  void compute_closest_points(std::span<const float> points, const ClosestOutput& out,
                              int nthreads);
  void compute_distance(std::span<const float> points, float* distance, int nthreads);
  void compute_signed_distance(std::span<const float> points, float* distance, int nthreads,
                               int nsamples);
  void compute_occupancy(std::span<const float> points, float* occupancy, int nthreads,
                         int nsamples);

  // The exact diff of this scene's backend against `reference` (a backend
  // spec) on the rays (6 floats each).
  api::DiffReport validate_rays(std::span<const float> rays, const std::string& reference);

  SceneInfo info() const;
  // A one-line warning when the backend's answers failed hprt's checks since
  // info().malformed_answers was `before` (a plugin's: include/hprt/plugin.h,
  // "Trust"), else "". Such hits come back as misses with t_hit NaN, such
  // occlusion answers as occluded.
  std::string malformed_since(uint64_t before) const;
  const api::Scene& scene() const { return scene_; }

 private:
  api::Backend& built();  // the backend, built or updated over the scene's current state
  const FaceNormals& face_normals();  // made on first use after a change
  // 6 floats per ray to hprt's records with the interval tnear, tfar.
  static void convert(std::span<const float> rays, float tnear, float tfar, api::Ray* out);

  api::Scene scene_;
  std::string backend_name_;
  api::Options options_;
  std::optional<api::Backend> backend_;
  bool stale_ = true;                     // the scene changed since the last build
  bool only_moved_ = false;               // ... and only by update_triangles (update, not build)
  std::unique_ptr<FaceNormals> normals_;  // the triangles' normals, null when stale
  // Queries may run at once from several threads (the Python module releases
  // the GIL); the first after a change builds the backend and normals under
  // prepare_ (info() takes it too, not to read a backend being rebuilt).
  // Adding or moving triangles holds use_ alone, so it waits for the queries
  // under way and the next ones wait for it; each query holds it shared.
  mutable std::mutex prepare_;
  mutable std::shared_mutex use_;
};

// Open3D's create_rays_pinhole: rays (height, width, 6) from the camera at
// `eye` looking at `center` with `up` and a horizontal field of view.
std::vector<float> create_rays_pinhole(double fov_deg, const double center[3], const double eye[3],
                                       const double up[3], int width_px, int height_px);
// The same from a 3x3 intrinsic matrix K and a 4x4 world-to-camera
// extrinsic matrix (row-major), pixel centres at (x + 0.5, y + 0.5).
std::vector<float> create_rays_pinhole(const double intrinsic[9], const double extrinsic[16],
                                       int width_px, int height_px);

}  // namespace hprt::raycasting
