#include "raycasting/raycasting_scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <stdexcept>
#include <utility>
#include <vector>

namespace hprt::raycasting {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr size_t kGrain = 4096;    // rays per task of the conversions
constexpr size_t kChunk = 262144;  // rays or points per chunk of a query's results

// nthreads <= 0 means every hardware thread, as in Open3D.
void check_nthreads(int nthreads) {
  if (nthreads > api::kMaxThreads)
    throw api::Error("nthreads: must be at most " + std::to_string(api::kMaxThreads) + ", got " +
                     std::to_string(nthreads));
}

// Runs f in an arena of `nthreads`, or where the caller runs for 0 or less
// (the backend's own threads, else every hardware thread).
template <typename F>
decltype(auto) with_nthreads(int nthreads, F&& f) {
  check_nthreads(nthreads);
  if (nthreads <= 0) return f();
  tbb::task_arena arena(nthreads);
  return arena.execute(std::forward<F>(f));
}

template <typename F>
void parallel_rays(size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) f(i);
                    });
}

void check_rays(std::span<const float> rays) {
  if (rays.size() % 6 != 0) throw std::invalid_argument("rays: not 6 floats per ray");
}

}  // namespace

RaycastingScene::RaycastingScene(int nthreads, const std::string& backend,
                                 const api::Options& options)
    : backend_name_(backend), options_(options) {
  check_nthreads(nthreads);
  if (nthreads > 0) options_["threads"] = std::to_string(nthreads);
  backend_.emplace(backend_name_, options_);  // bad names and options fail here, not later
}

uint32_t RaycastingScene::add_triangles(std::span<const float> vertices,
                                        std::span<const uint32_t> indices, bool shared) {
  const std::unique_lock change(use_);
  const uint32_t id =
      shared ? scene_.add_mesh_shared(vertices, indices) : scene_.add_mesh(vertices, indices);
  stale_ = true;
  normals_.reset();
  only_moved_ = false;
  return id;
}

uint32_t RaycastingScene::add_triangles(const std::string& path) {
  const api::MeshArrays m = api::load_mesh(path);
  return add_triangles(m.vertices, m.indices, /*shared=*/false);
}

void RaycastingScene::update_triangles(uint32_t id, std::span<const float> vertices,
                                       bool /*shared*/) {
  const std::unique_lock change(use_);
  if (id >= scene_.mesh_count())
    throw api::Error("geometry_id: no geometry " + std::to_string(id) + " (the scene has " +
                     std::to_string(scene_.mesh_count()) + ")");
  if (vertices.size() != 3 * scene_.vertex_count(id))
    throw api::Error("vertex_positions: expected " + std::to_string(scene_.vertex_count(id)) +
                     " vertices (as added), got " + std::to_string(vertices.size() / 3));
  // A shared mesh shares the new array, a copied one copies it (Scene::set_vertices).
  scene_.set_vertices(id, vertices);
  if (!stale_) only_moved_ = true;
  stale_ = true;
  normals_.reset();
}

api::Backend& RaycastingScene::built() {
  const std::lock_guard lock(prepare_);
  if (stale_) {
    if (only_moved_)
      backend_->update(scene_);
    else
      backend_->build(scene_);
    stale_ = false;
    only_moved_ = false;
  }
  return *backend_;
}

const FaceNormals& RaycastingScene::face_normals() {
  const std::lock_guard lock(prepare_);
  if (!normals_) normals_ = std::make_unique<FaceNormals>(scene_);
  return *normals_;
}

void RaycastingScene::convert(std::span<const float> rays, float tnear, float tfar, api::Ray* out) {
  parallel_rays(rays.size() / 6, [&](size_t i) {
    const float* r = rays.data() + 6 * i;
    out[i] = {r[0], r[1], r[2], tnear, r[3], r[4], r[5], tfar};
  });
}

namespace {

// Calls f(begin, end) over [0, n) in parallel, kGrain at a time.
template <typename F>
void parallel_ranges(size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain),
                    [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
}

}  // namespace

// The ray queries hand the backend the caller's array itself
// (api::RayArray), which it reads a block at a time; list_intersections a
// chunk at a time, so the backend's hit lists stay a few MB.
void RaycastingScene::cast_rays(std::span<const float> rays, const CastOutput& out, int nthreads) {
  const std::shared_lock use(use_);
  check_rays(rays);
  check_nthreads(nthreads);  // before a build the call would otherwise start
  api::Backend& b = built();
  const size_t n = rays.size() / 6;
  with_nthreads(nthreads, [&] {
    b.intersect(api::RayArray{rays, 0.0f, kInf}, api::HitColumns{{out.t_hit, n},
                                                                 {out.geometry_ids, n},
                                                                 {out.primitive_ids, n},
                                                                 {out.primitive_uvs, 2 * n},
                                                                 {out.primitive_normals, 3 * n}});
  });
}

void RaycastingScene::test_occlusions(std::span<const float> rays, float tnear, float tfar,
                                      uint8_t* occluded, int nthreads) {
  const std::shared_lock use(use_);
  // Rays with tnear < 0 or not tnear <= tfar miss (core/ray.h): as the
  // interval is the caller's choice here, such a choice is an error.
  if (!(tnear >= 0.0f && tnear <= tfar))
    throw std::invalid_argument("tnear, tfar: need 0 <= tnear <= tfar, got " +
                                std::to_string(tnear) + ", " + std::to_string(tfar));
  check_rays(rays);
  check_nthreads(nthreads);  // before a build the call would otherwise start
  api::Backend& b = built();
  const uint64_t malformed_before = b.info().malformed_answers;
  const size_t n = rays.size() / 6;
  with_nthreads(nthreads, [&] { b.occluded(api::RayArray{rays, tnear, tfar}, {occluded, n}); });
  // A plugin's malformed byte (neither 0 nor 1) reads as occluded: stored as
  // 1, since Python's bool arrays hold only 0 and 1.
  if (b.info().malformed_answers != malformed_before)
    for (size_t i = 0; i < n; ++i) occluded[i] = occluded[i] != 0;
}

void RaycastingScene::count_intersections(std::span<const float> rays, int32_t* counts,
                                          int nthreads) {
  const std::shared_lock use(use_);
  check_rays(rays);
  check_nthreads(nthreads);  // before a build the call would otherwise start
  api::Backend& b = built();
  // int32 and uint32 may alias; a count never reaches 2^31 (one per triangle).
  with_nthreads(nthreads, [&] {
    b.count(api::RayArray{rays, 0.0f, kInf},
            {reinterpret_cast<uint32_t*>(counts), rays.size() / 6});
  });
}

IntersectionLists RaycastingScene::list_intersections(std::span<const float> rays, int nthreads) {
  const std::shared_lock use(use_);
  check_rays(rays);
  check_nthreads(nthreads);  // before a build the call would otherwise start
  api::Backend& b = built();
  IntersectionLists out;
  const auto run = [&] {
    const size_t n = rays.size() / 6;
    out.ray_splits.assign(1, 0);
    for (size_t begin = 0; begin < n; begin += kChunk) {
      const size_t count = std::min(kChunk, n - begin);
      const api::Backend::HitLists lists =
          b.intersect_all(api::RayArray{rays.subspan(6 * begin, 6 * count), 0.0f, kInf},
                          std::numeric_limits<uint32_t>::max());
      for (size_t k = 0; k < count; ++k) {
        for (uint64_t j = lists.offsets[k]; j < lists.offsets[k + 1]; ++j) {
          const api::Hit& h = lists.hits[j];
          out.ray_ids.push_back(uint32_t(begin + k));
          out.geometry_ids.push_back(h.geom_id);
          out.primitive_ids.push_back(h.prim_id);
          out.t_hit.push_back(h.t);
          out.primitive_uvs.push_back(h.u);
          out.primitive_uvs.push_back(h.v);
        }
        if (out.t_hit.size() > size_t(std::numeric_limits<uint32_t>::max()))
          throw api::Error("list_intersections: more than 2^32-1 intersections");
        out.ray_splits.push_back(uint32_t(out.t_hit.size()));
      }
    }
  };
  with_nthreads(nthreads, run);
  return out;
}

namespace {
void check_points(std::span<const float> points) {
  if (points.size() % 3 != 0) throw std::invalid_argument("query_points: not 3 floats per point");
}
void check_nsamples(int nsamples) {
  if (nsamples < 1 || nsamples % 2 != 1)
    throw api::Error("nsamples: must be odd and >= 1, got " + std::to_string(nsamples));
}

// Points go through in chunks, as rays do: f(points of the chunk, first
// point's index, count) with `nthreads` as cast_rays takes it.
template <typename F>
void for_point_chunks(std::span<const float> points, int nthreads, F&& f) {
  const auto run = [&] {
    const size_t n = points.size() / 3;
    for (size_t begin = 0; begin < n; begin += kChunk) {
      const size_t count = std::min(kChunk, n - begin);
      f(points.subspan(3 * begin, 3 * count), begin, count);
    }
  };
  with_nthreads(nthreads, run);
}
}  // namespace

void RaycastingScene::compute_closest_points(std::span<const float> points,
                                             const ClosestOutput& out, int nthreads) {
  const std::shared_lock use(use_);
  check_points(points);
  check_nthreads(nthreads);
  api::Backend& b = built();
  std::vector<api::Backend::ClosestPoint> c(std::min(points.size() / 3, kChunk));
  for_point_chunks(points, nthreads, [&](std::span<const float> p, size_t begin, size_t count) {
    const FaceNormals& normals = face_normals();
    b.closest(p, {c.data(), count});
    parallel_ranges(count, [&](size_t k0, size_t k1) {
      for (size_t k = k0; k < k1; ++k) {
        const api::Backend::ClosestPoint& q = c[k];
        const size_t i = begin + k;
        out.points[3 * i] = q.x;
        out.points[3 * i + 1] = q.y;
        out.points[3 * i + 2] = q.z;
        out.geometry_ids[i] = q.geom_id;
        out.primitive_ids[i] = q.prim_id;
        out.primitive_uvs[2 * i] = q.u;
        out.primitive_uvs[2 * i + 1] = q.v;
      }
      normals.write(
          k0, k1, [&](size_t k) { return c[k].geom_id; }, [&](size_t k) { return c[k].prim_id; },
          [&](size_t k) { return out.primitive_normals + 3 * (begin + k); });
    });
  });
}

void RaycastingScene::compute_distance(std::span<const float> points, float* distance,
                                       int nthreads) {
  const std::shared_lock use(use_);
  check_points(points);
  check_nthreads(nthreads);
  api::Backend& b = built();
  std::vector<api::Backend::ClosestPoint> c(std::min(points.size() / 3, kChunk));
  for_point_chunks(points, nthreads, [&](std::span<const float> p, size_t begin, size_t count) {
    b.closest(p, {c.data(), count});
    for (size_t k = 0; k < count; ++k) distance[begin + k] = c[k].distance;
  });
}

void RaycastingScene::compute_signed_distance(std::span<const float> points, float* distance,
                                              int nthreads, int nsamples) {
  const std::shared_lock use(use_);
  check_points(points);
  check_nsamples(nsamples);
  check_nthreads(nthreads);
  api::Backend& b = built();
  std::vector<api::Backend::ClosestPoint> c(std::min(points.size() / 3, kChunk));
  std::vector<uint8_t> where(c.size());
  for_point_chunks(points, nthreads, [&](std::span<const float> p, size_t begin, size_t count) {
    b.closest(p, {c.data(), count});
    b.inside(p, {where.data(), count});
    for (size_t k = 0; k < count; ++k)
      distance[begin + k] =
          where[k] == api::Backend::kOnSurface
              ? 0.0f
              : (where[k] == api::Backend::kInside ? -c[k].distance : c[k].distance);
  });
}

void RaycastingScene::compute_occupancy(std::span<const float> points, float* occupancy,
                                        int nthreads, int nsamples) {
  const std::shared_lock use(use_);
  check_points(points);
  check_nsamples(nsamples);
  check_nthreads(nthreads);
  api::Backend& b = built();
  std::vector<uint8_t> where(std::min(points.size() / 3, kChunk));
  for_point_chunks(points, nthreads, [&](std::span<const float> p, size_t begin, size_t count) {
    b.inside(p, {where.data(), count});
    for (size_t k = 0; k < count; ++k)
      occupancy[begin + k] = where[k] == api::Backend::kOutside ? 0.0f : 1.0f;
  });
}

api::DiffReport RaycastingScene::validate_rays(std::span<const float> rays,
                                               const std::string& reference) {
  const std::shared_lock use(use_);
  api::Backend& b = built();
  api::Backend ref(reference);
  ref.build(scene_);
  check_rays(rays);
  std::vector<api::Ray> r(rays.size() / 6);
  convert(rays, 0.0f, kInf, r.data());
  return api::diff(scene_, b, ref, r);
}

SceneInfo RaycastingScene::info() const {
  const std::shared_lock use(use_);
  const std::lock_guard lock(prepare_);
  SceneInfo i;
  i.meshes = scene_.mesh_count();
  i.triangles = scene_.triangle_count();
  i.normals_bytes = normals_ ? normals_->memory_bytes() : 0;
  const api::BackendInfo b = backend_->info();
  i.backend = b.name;
  i.malformed_answers = b.malformed_answers;  // the backend's count since it was made
  if (!stale_ || only_moved_) {
    i.build_ms = b.build_ms;
    i.memory_bytes = b.memory_bytes;
  }
  return i;
}

std::string RaycastingScene::malformed_since(uint64_t before) const {
  const SceneInfo i = info();
  if (i.malformed_answers <= before) return {};
  return i.backend + " gave " + std::to_string(i.malformed_answers - before) +
         " malformed answers (t outside the ray's interval, ids out of range, u/v outside the "
         "triangle, a record left unwritten, or an occlusion byte not 0/1): hits returned as "
         "misses with t_hit NaN, occlusions as occluded";
}

namespace {

// Rays through pixel centres: origin `eye`, direction M * (x + 0.5, y + 0.5, 1)
// with M = R^T K^-1 (camera to world), not normalised (as Open3D's).
std::vector<float> pinhole_rays(const double m[3][3], const double eye[3], int w, int h) {
  if (w <= 0 || h <= 0) throw api::Error("width_px, height_px: must be positive");
  if (size_t(w) * size_t(h) > api::kMaxRays)
    throw api::Error("width_px, height_px: " + std::to_string(w) + " x " + std::to_string(h) +
                     " rays, more than " + std::to_string(api::kMaxRays));
  std::vector<float> rays(size_t(w) * size_t(h) * 6);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double p[3] = {x + 0.5, y + 0.5, 1.0};
      float* r = &rays[(size_t(y) * size_t(w) + size_t(x)) * 6];
      for (int k = 0; k < 3; ++k) {
        r[k] = float(eye[k]);
        r[3 + k] = float(m[k][0] * p[0] + m[k][1] * p[1] + m[k][2] * p[2]);
      }
    }
  return rays;
}

double norm3(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace

std::vector<float> create_rays_pinhole(const double intrinsic[9], const double extrinsic[16],
                                       int width_px, int height_px) {
  // K^-1 for K = [[fx, s, cx], [0, fy, cy], [0, 0, 1]] (row-major).
  const double fx = intrinsic[0], s = intrinsic[1], cx = intrinsic[2], fy = intrinsic[4],
               cy = intrinsic[5];
  if (!(fx != 0.0 && fy != 0.0) || intrinsic[3] != 0.0 || intrinsic[6] != 0.0 ||
      intrinsic[7] != 0.0 || intrinsic[8] != 1.0)
    throw api::Error(
        "intrinsic_matrix: expected [[fx, s, cx], [0, fy, cy], [0, 0, 1]], fx, fy != 0");
  const double kinv[3][3] = {{1.0 / fx, -s / (fx * fy), (s * cy - cx * fy) / (fx * fy)},
                             {0.0, 1.0 / fy, -cy / fy},
                             {0.0, 0.0, 1.0}};
  // Extrinsic [R t; 0 1] maps world to camera: camera centre -R^T t, M = R^T K^-1.
  double m[3][3], eye[3];
  for (int i = 0; i < 3; ++i) {
    eye[i] = 0.0;
    for (int k = 0; k < 3; ++k) eye[i] -= extrinsic[4 * k + i] * extrinsic[4 * k + 3];
    for (int j = 0; j < 3; ++j) {
      m[i][j] = 0.0;
      for (int k = 0; k < 3; ++k) m[i][j] += extrinsic[4 * k + i] * kinv[k][j];
    }
  }
  return pinhole_rays(m, eye, width_px, height_px);
}

std::vector<float> create_rays_pinhole(double fov_deg, const double center[3], const double eye[3],
                                       const double up[3], int width_px, int height_px) {
  if (!(fov_deg > 0.0 && fov_deg < 180.0))
    throw api::Error("fov_deg: must be in (0, 180), got " + std::to_string(fov_deg));
  if (width_px <= 0 || height_px <= 0) throw api::Error("width_px, height_px: must be positive");
  const double f = 0.5 * width_px / std::tan(0.5 * fov_deg * M_PI / 180.0);
  const double k[9] = {f, 0.0, 0.5 * width_px, 0.0, f, 0.5 * height_px, 0.0, 0.0, 1.0};
  // Rows of R: right, down-facing up, forward (Open3D's look-at convention).
  double r[3][3];
  const double fwd[3] = {center[0] - eye[0], center[1] - eye[1], center[2] - eye[2]};
  const double fn = norm3(fwd), un = norm3(up);
  if (!(fn > 0.0) || !(un > 0.0)) throw api::Error("center, eye, up: eye == center or up == 0");
  for (int i = 0; i < 3; ++i) r[2][i] = fwd[i] / fn, r[1][i] = up[i] / un;
  auto cross = [](const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  };
  cross(r[1], r[2], r[0]);
  const double rn = norm3(r[0]);
  if (!(rn > 0.0)) throw api::Error("up: parallel to the view direction");
  for (double& x : r[0]) x /= rn;
  cross(r[2], r[0], r[1]);
  double e[16] = {0};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) e[4 * i + j] = r[i][j];
    e[4 * i + 3] = -(r[i][0] * eye[0] + r[i][1] * eye[1] + r[i][2] * eye[2]);
  }
  e[15] = 1.0;
  return create_rays_pinhole(k, e, width_px, height_px);
}

}  // namespace hprt::raycasting
