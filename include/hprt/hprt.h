// hprt's public C++ API: scenes from arrays or files, any backend by name
// (hprt's BVH, Embree, or a plugin), ray queries over spans, an exact diff of
// two backends, and Whitted renders into a buffer. Link hprt::hprt:
//
//   find_package(hprt 0.1 REQUIRED)
//   target_link_libraries(app PRIVATE hprt::hprt)
//
// Everything here is in namespace hprt::api and declared in this header (and
// <hprt/plugin.h>, whose ray and hit records it uses); nothing else of hprt's
// source is part of the API. C++20.
//
// Errors: every function throws hprt::api::Error carrying the one-line
// message the command line prints ("path: problem" for files, "key: problem"
// for options), std::invalid_argument for a programming error (a span of
// the wrong size, an unknown geom_id), std::logic_error for a query before
// build() on the embree and plugin backends (the bvh backend answers
// misses), std::runtime_error when Embree itself fails, and std::bad_alloc
// when memory runs out.
//
// Threads: a Backend built with the option threads=N runs its build and
// queries in a pool of N threads (0 = every hardware thread); without it,
// in the caller's oneTBB task arena (by default every hardware thread; inside
// a tbb::task_arena, that arena). Queries are const and may run
// concurrently on one built backend; build() and update() may not.
#pragma once

#include <hprt/plugin.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#if defined(_WIN32)
#define HPRT_API __declspec(dllimport)
#else
#define HPRT_API __attribute__((visibility("default")))
#endif

namespace hprt::api {

// The library's version, e.g. "0.1.0".
HPRT_API const char* version();

class HPRT_API Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A ray: origin, tnear, direction (any nonzero length), tfar. A hit: t, the
// barycentrics u, v of vertices 1 and 2, the mesh (geom_id, in order of
// add_mesh) and the triangle in it (prim_id). A miss has t = +inf and both
// ids kInvalidId. Semantics are Embree 3's: closest hit with t in
// (tnear, tfar], double-sided triangles; rays with a NaN, infinite or
// too-large component, a zero direction, tnear < 0 or tnear > tfar miss.
// A plugin's malformed hit comes back as a miss with t = NaN (counted in
// BackendInfo::malformed_answers; <hprt/plugin.h> says what is malformed).
using Ray = hprt_ray;
using Hit = hprt_hit;
inline constexpr uint32_t kInvalidId = 0xFFFFFFFFu;

// Triangle meshes (geom_id = order of adding), plus the camera and lights a
// render uses. A scene made from arrays gets a camera that frames it from +z
// and a light at the camera; a scene file brings its own.
class HPRT_API Scene {
 public:
  Scene();
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;

  // A mesh file (OBJ, PLY, optionally .gz) or a JSON scene file, as the
  // command line reads them.
  static Scene from_file(const std::string& path);

  // Adds a mesh: xyz per vertex (vertices.size() = 3 * vertex count) and
  // three indices per triangle. The arrays are copied. An index out of
  // range throws Error; non-finite vertices and zero-area triangles are
  // kept and never hit. The scene's camera is reset to frame all its meshes
  // from +z (also for a scene from a file). Returns the mesh's geom_id.
  uint32_t add_mesh(std::span<const float> vertices, std::span<const uint32_t> indices);

  // The same without a copy: the scene keeps pointers to the caller's arrays,
  // which must stay alive and unmoved as long as the scene and the backends
  // built over it are used. The caller may change the vertices in place
  // between queries and then call Backend::update(). (The embree backend
  // copies the vertices all the same: Embree reads 4 bytes past the last
  // vertex, which a caller's array need not have.)
  uint32_t add_mesh_shared(std::span<const float> vertices, std::span<const uint32_t> indices);

  // Moves the vertices of mesh geom_id (same vertex count): a deformed
  // frame. Call update() on the backends built over the scene before their
  // next query (until then their answers are undefined: the embree backend
  // may read the new vertices against its old tree). A
  // shared mesh then shares `vertices` instead of its old array; any other
  // mesh copies them.
  void set_vertices(uint32_t geom_id, std::span<const float> vertices);
  bool shared(uint32_t geom_id) const;  // whether mesh geom_id views the caller's arrays

  size_t mesh_count() const;
  size_t triangle_count() const;
  size_t vertex_count(uint32_t geom_id) const;
  // xyz per vertex and 3 per triangle, as stored (the caller's own arrays for
  // a shared mesh; else valid until the next add_mesh or set_vertices).
  std::span<const float> vertices(uint32_t geom_id) const;
  std::span<const uint32_t> indices(uint32_t geom_id) const;
  // The unit geometric normal of each triangle of mesh geom_id, 3 floats per
  // triangle (out.size() >= 3 * its triangle count), as
  // Backend::intersect reports it in HitColumns::normal for a hit.
  void normals(uint32_t geom_id, std::span<float> out) const;
  // Bounding box of the finite vertices: min x, y, z, max x, y, z.
  std::array<float, 6> bounds() const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Closest hits as separate arrays ("columns", as numpy and Open3D users
// hold them) for Backend::intersect. Each span is empty (not written) or
// holds at least one entry per ray (uv two, normal three): t (+inf on a
// miss), geom_id and prim_id (kInvalidId on a miss), uv (u, v; 0 on a miss)
// and normal, the hit triangle's unit geometric normal: (v1 - v0) x
// (v2 - v0) of the triangle as added, normalised in double and rounded to
// float, so every backend gives the same bits (0 on a miss). The bvh
// backend writes the columns while it traces (the normal from the vertices
// its test read, or with isect=mt from a table it makes at the first call
// with normals after a build or update: 12 bytes per triangle); the others
// trace into records and copy them.
struct HitColumns {
  std::span<float> t;
  std::span<uint32_t> geom_id;
  std::span<uint32_t> prim_id;
  std::span<float> uv;
  std::span<float> normal;
};

// Rays as numpy and Open3D users hold them: six floats each (origin x, y,
// z, direction x, y, z), all with the same tnear and tfar, the same rays as
// Ray records with those fields (hits with t in (tnear, tfar]).
// Backend::intersect (into HitColumns), occluded, count and intersect_all
// take them without a copy of the whole batch as records: the bvh backend
// converts a block of rays at a time as it traces, the others a chunk, a
// packet or a ray at a time. A rays.size() that is
// not a multiple of 6 throws std::invalid_argument; result spans are sized
// by the ray count, rays.size() / 6.
struct RayArray {
  std::span<const float> rays;
  float tnear = 0.0f;
  float tfar = std::numeric_limits<float>::infinity();
};

// Backend options by the command line's names, without the dashes:
// threads, builder (sweep|presorted|binned|parallel|morton), bins, leaf_size,
// sah_traversal, sah_intersection, sah_leaf_block, isect (watertight|mt),
// layout (bvh2|bvh4|bvh8), quality (low|medium|high|refit), robust (on|off),
// update (auto|rebuild|refit|adaptive), adaptive_factor. Values as on the command
// line ("32", "morton"); an unknown key or a bad value throws Error
// "key: problem". Options that do not apply to a backend are ignored by it.
// threads is 0 (every hardware thread) to kMaxThreads.
using Options = std::map<std::string, std::string>;
inline constexpr int kMaxThreads = 4096;

struct BackendInfo {
  std::string name;       // configuration, e.g. "bvh/parallel/watertight", "embree/medium"
  double build_ms = 0.0;  // the last build() or update()
  // The acceleration structure (0 for plugins: ABI v1 has no report), and
  // the bvh backend's normal table while it holds one (HitColumns).
  size_t memory_bytes = 0;
  bool rebuilt = true;             // update(): rebuilt rather than refitted
  uint64_t malformed_answers = 0;  // plugins: answers that failed hprt's checks so far
};

class HPRT_API Backend {
 public:
  // name: "bvh" (hprt's BVH, the default), "embree", or
  // "plugin:PATH.so[:OPTIONS]" (a library implementing <hprt/plugin.h>).
  // Throws Error for an unknown name or option, or a plugin that cannot be
  // loaded or created.
  explicit Backend(const std::string& name = "bvh", const Options& options = {});
  ~Backend();
  Backend(Backend&&) noexcept;
  Backend& operator=(Backend&&) noexcept;

  // Builds over the scene, which must outlive the backend's queries (the
  // embree backend shares its vertex arrays).
  void build(const Scene& scene);
  // After Scene::set_vertices: bvh refits or rebuilds per the update option,
  // embree refits with quality=refit and rebuilds otherwise, a plugin runs
  // its update() (or build()). A changed set of meshes means a full build.
  void update(const Scene& scene);

  // hits.size() and occluded.size() must be at least the number of rays.
  // occluded: 1 when some hit has t in (tnear, tfar], else 0.
  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const;
  // The same answers written as separate arrays (HitColumns) instead of
  // records, with each hit triangle's normal if asked for.
  void intersect(std::span<const Ray> rays, const HitColumns& out) const;
  void intersect(const RayArray& rays, const HitColumns& out) const;
  void occluded(std::span<const Ray> rays, std::span<uint8_t> occluded) const;
  void occluded(const RayArray& rays, std::span<uint8_t> occluded) const;

  // Surface crossings along each ray in (tnear, tfar]: counts[i] for
  // rays[i] (counts.size() >= rays.size()). The bvh backend (watertight test,
  // the default) counts each crossing exactly once: a ray exactly through an
  // edge or vertex shared by several triangles hits one of them (a fill
  // rule), so the parity tells inside from outside for closed meshes. Embree
  // counts every triangle its test hits (a shared edge may count twice or
  // not at all). Plugins cannot answer: Error.
  void count(std::span<const Ray> rays, std::span<uint32_t> counts) const;
  void count(const RayArray& rays, std::span<uint32_t> counts) const;

  // Every crossing along each ray in (tnear, tfar], in order of t (then
  // geom_id, prim_id), at most max_per_ray per ray: ray i's are
  // hits[offsets[i] .. offsets[i + 1]), truncated[i] = 1 when the bound cut
  // its list (the nearest are kept).
  struct HitLists {
    std::vector<uint64_t> offsets;  // rays + 1
    std::vector<Hit> hits;
    std::vector<uint8_t> truncated;
  };
  HitLists intersect_all(std::span<const Ray> rays, uint32_t max_per_ray = 1024) const;
  HitLists intersect_all(const RayArray& rays, uint32_t max_per_ray = 1024) const;

  // Point queries; `points` holds x, y, z per point (points.size() a
  // multiple of 3), the results one per point.
  //
  // inside: kOutside, kInside or kOnSurface against the scene's closed
  // meshes, by the parity of the surface crossings of a ray from the point.
  // The bvh backend decides exactly, whatever the point (on a vertex or edge
  // plane, exactly on a triangle: kOnSurface); Embree by the parity of its
  // own crossing count, on the surface where its closest point is at
  // distance 0. A point with a non-finite or larger than 1.844e18
  // coordinate is outside. Plugins cannot answer: Error.
  enum Location : uint8_t { kOutside = 0, kInside = 1, kOnSurface = 2 };
  void inside(std::span<const float> points, std::span<uint8_t> locations) const;

  // closest: the nearest point of any triangle within max_distance
  // (inclusive), with its distance, the barycentrics u, v of vertices 1 and
  // 2, and its triangle; among triangles at exactly the same distance, the
  // smallest (geom_id, prim_id). Nothing within reach (or a point as above):
  // x = y = z = distance = +inf, u = v = 0, both ids kInvalidId. Distances
  // are computed in double from the float inputs, the same way on every
  // backend.
  struct ClosestPoint {
    float x, y, z, distance, u, v;
    uint32_t geom_id, prim_id;
  };
  void closest(std::span<const float> points, std::span<ClosestPoint> closest,
               float max_distance = std::numeric_limits<float>::infinity()) const;

  BackendInfo info() const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Memory for result arrays that a caller hands on and frees later, as the
// Python module does with the numpy arrays a query returns. Blocks of 2 MiB
// or more are kept when released (up to max_bytes in all, the oldest
// dropped first) and handed out again to a request of a close size, so a
// query repeated with fresh result arrays writes into pages already faulted
// in, not into pages the kernel must map and zero on first touch. Smaller
// blocks come from the heap. Thread-safe. Every block must be released
// before the ResultMemory goes (share it, e.g. through a shared_ptr held by
// each block's owner).
class HPRT_API ResultMemory {
 public:
  explicit ResultMemory(size_t max_bytes = size_t{256} << 20);
  ~ResultMemory();
  ResultMemory(const ResultMemory&) = delete;
  ResultMemory& operator=(const ResultMemory&) = delete;

  // At least `bytes`, 64-byte aligned (2 MiB for large blocks), uninitialised.
  void* acquire(size_t bytes);
  // A block from acquire (nullptr: nothing).
  void release(void* p) noexcept;
  // Bytes of released blocks held for reuse.
  size_t cached_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A mesh file (OBJ, PLY, optionally .gz) as arrays: xyz per vertex, three
// indices per triangle, the whole file as one mesh.
struct MeshArrays {
  std::vector<float> vertices;
  std::vector<uint32_t> indices;
};
HPRT_API MeshArrays load_mesh(const std::string& path);

// Ray sets as `hprt rays` makes them: kind primary, shadow, reflection,
// diffuse, random, vertex-probe, edge-probe, grazing, axis, nan (the command line's --kind
// names); deterministic for a seed. Throws Error for an unknown kind or a
// count above kMaxRays.
inline constexpr size_t kMaxRays = 1'000'000'000;
HPRT_API std::vector<Ray> make_rays(const Scene& scene, const std::string& kind, size_t count,
                                    uint64_t seed = 1);

// One ray's verdict in a diff. Agree: same triangle at the same t (or both
// miss); tie: different triangles at the same t, both really hit. Otherwise
// the exact arbiter says which answer is right.
enum class Verdict : uint8_t {
  kAgree,
  kTie,
  kBackendRight,
  kReferenceRight,
  kBothRight,
  kBothWrong
};

struct DiffReport {
  size_t rays = 0, agree = 0, ties = 0, mismatches = 0;
  size_t backend_right = 0, reference_right = 0, both_right = 0, both_wrong = 0;
  size_t backend_malformed = 0, reference_malformed = 0;  // answers failing hprt's checks
  double max_rel_t_error = 0.0;   // agreeing rays, backend against reference
  std::vector<Verdict> verdicts;  // one per ray
  std::string summary;            // the lines `hprt validate rays` prints
  // Rays where the backend's answer is wrong: reference right or both wrong.
  size_t backend_wrong() const { return reference_right + both_wrong; }
};

// Traces `rays` through both built backends (closest hit, or occlusion when
// `occluded`) and settles every disagreement with the exact arbiter.
HPRT_API DiffReport diff(const Scene& scene, const Backend& backend, const Backend& reference,
                         std::span<const Ray> rays, bool occluded = false);

// Linear float RGB, row 0 at the top: pixel (x, y) is rgb[3 * (y * width + x) + c].
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;
};

// A Whitted render (shadows, mirror reflections) of the scene through its
// camera with a built backend. width/height 0 keep the camera's; one alone
// keeps its aspect ratio; each at most 65536 (std::invalid_argument).
HPRT_API Image render(const Scene& scene, const Backend& backend, int width = 0, int height = 0);

}  // namespace hprt::api
