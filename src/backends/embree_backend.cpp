// Intel Embree 3 as the reference backend: one triangle geometry per mesh
// (geomID = mesh index) sharing the mesh's own vertex and index arrays (so the
// Scene must outlive every query), build quality and robust flag as options;
// rays traced in parallel (oneTBB, caller's task arena) as 16-ray packets when
// coherent, else with rtcIntersect1/rtcOccluded1; count and all queries
// through a context filter function; closest points through rtcPointQuery
// with the usual closest-point callback, inside through both (the parity of
// the crossings along core/point_query.h's ray, on the surface where the
// closest point is at distance 0).
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "backends/embree_backend.h"
#include "backends/embree_device.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/ray_coherence.h"
#include "core/stopwatch.h"
#include "core/triangle_mesh.h"

namespace hprt {
namespace {

static_assert(sizeof(Vec3f) == 12 && sizeof(Vec3u) == 12, "Embree float3/uint3 layout");

constexpr size_t kBlock = 256;  // rays per parallel task (grain size)
constexpr size_t kPacket = 16;  // rtcIntersect16 / rtcOccluded16

RTCBuildQuality parse_quality(const std::string& q) {
  if (q == "low") return RTC_BUILD_QUALITY_LOW;
  if (q == "medium") return RTC_BUILD_QUALITY_MEDIUM;
  if (q == "high") return RTC_BUILD_QUALITY_HIGH;
  if (q == "refit") return RTC_BUILD_QUALITY_REFIT;
  throw OptionError(
      "quality", "unknown embree build quality '" + q + "' (expected low, medium, high or refit)");
}

// Embree 3 requires a ray segment inside [0, inf] and org/dir components of
// magnitude <= FLT_LARGE (1.844e18, RayK::valid() in kernels/common/ray.h);
// anything else is undefined, and Debian's build even aborts on tnear < 0
// (an assert in bvh_intersector1.cpp). hprt defines all such rays, and those
// with a zero direction, as misses, answered here without calling Embree.

inline void to_embree(const Ray& r, RTCRay& e) {
  e.org_x = r.org.x;
  e.org_y = r.org.y;
  e.org_z = r.org.z;
  e.tnear = r.tnear;
  e.dir_x = r.dir.x;
  e.dir_y = r.dir.y;
  e.dir_z = r.dir.z;
  e.time = 0.0f;
  e.tfar = r.tfar;
  e.mask = 0xFFFFFFFFu;
  e.id = 0;
  e.flags = 0;
}

class EmbreeIntersector final : public Intersector {
 public:
  explicit EmbreeIntersector(const BackendOptions& options)
      : options_(options),
        quality_(parse_quality(options.embree_quality)),
        device_(resolve_threads(options.threads)) {
    info_.name = "embree/" + options.embree_quality + (options.embree_robust ? "/robust" : "");
  }

  ~EmbreeIntersector() override { release_scene(); }

  void build(const Scene& scene) override {
    const auto start = Clock::now();
    build_scene(scene);
    info_.build_ms = ms_since(start);
    info_.rebuilt = true;
    info_.memory_bytes = device_.current_bytes();
  }

  // The caller moved vertices in place (same meshes, same vertex and
  // triangle counts, same arrays): tell Embree the vertex buffers changed and
  // recommit, which refits with quality "refit" and rebuilds otherwise. Any
  // other change (new arrays, new topology) is a full build.
  void update(const Scene& scene) override {
    const auto start = Clock::now();
    if (!same_layout(scene)) {
      build_scene(scene);
      info_.rebuilt = true;
    } else {
      for (size_t i = 0; i < geoms_.size(); ++i) {
        if (!geoms_[i].geom) continue;
        const TriangleMesh& m = scene.meshes[i];
        if (!geoms_[i].copy.empty())
          std::copy(m.positions.begin(), m.positions.end(), geoms_[i].copy.begin());
        rtcUpdateGeometryBuffer(geoms_[i].geom, RTC_BUFFER_TYPE_VERTEX, 0);
        rtcCommitGeometry(geoms_[i].geom);
      }
      device_.check("update geometry");
      release_query_scene();
      rtcCommitScene(scene_);
      device_.check("rtcCommitScene");
      info_.rebuilt = quality_ != RTC_BUILD_QUALITY_REFIT;
    }
    info_.build_ms = ms_since(start);
    info_.memory_bytes = device_.current_bytes();
  }

  // Rays go in fixed groups of 16 (ray i is in group i / 16, whatever the
  // thread count). A full group of valid, coherent rays is traced as one
  // rtcIntersect16 packet, anything else ray by ray with rtcIntersect1.
  // Measured on a 1M-triangle sphere, one thread: packets trace primary rays
  // ~1.5x faster but random rays ~2x slower, with bit-identical answers.
  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    if (hits.size() < rays.size())
      throw std::invalid_argument("intersect: fewer hit slots than rays");
    if (!scene_) throw std::logic_error("embree: intersect() before build()");
    const size_t groups = (rays.size() + kPacket - 1) / kPacket;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, groups, kBlock / kPacket),
                      [&](const tbb::blocked_range<size_t>& range) {
                        RTCIntersectContext context;
                        rtcInitIntersectContext(&context);
                        for (size_t g = range.begin(); g != range.end(); ++g) {
                          const size_t first = g * kPacket;
                          const size_t count = std::min(kPacket, rays.size() - first);
                          const Ray* r = rays.data() + first;
                          Hit* h = hits.data() + first;
                          if (count == kPacket && coherent(r))
                            intersect_packet(context, r, h);
                          else
                            for (size_t i = 0; i < count; ++i) intersect_one(context, r[i], h[i]);
                        }
                      });
  }

  void occluded(const RayInput& rays, std::span<uint8_t> result) const override {
    if (result.size() < rays.size())
      throw std::invalid_argument("occluded: fewer result slots than rays");
    if (!scene_) throw std::logic_error("embree: occluded() before build()");
    const size_t groups = (rays.size() + kPacket - 1) / kPacket;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, groups, kBlock / kPacket),
                      [&](const tbb::blocked_range<size_t>& range) {
                        RTCIntersectContext context;
                        rtcInitIntersectContext(&context);
                        alignas(64) Ray buf[kPacket];  // six-float rays as records
                        for (size_t g = range.begin(); g != range.end(); ++g) {
                          const size_t first = g * kPacket;
                          const size_t count = std::min(kPacket, rays.size() - first);
                          const Ray* r = rays.block(first, count, buf);
                          uint8_t* o = result.data() + first;
                          if (count == kPacket && coherent(r))
                            occluded_packet(context, r, o);
                          else
                            for (size_t i = 0; i < count; ++i) o[i] = occluded_one(context, r[i]);
                        }
                      });
  }

  // Every hit through Embree: the same rays with a context filter function
  // that records each hit Embree's test finds and rejects it, so traversal
  // goes on (embree#188's recipe). Rays one by one (rtcIntersect1).
  void count(const RayInput& rays, std::span<uint32_t> counts) const override {
    if (counts.size() < rays.size())
      throw std::invalid_argument("count: fewer result slots than rays");
    RTCScene scene = query_scene();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), kBlock),
                      [&](const tbb::blocked_range<size_t>& range) {
                        std::vector<Hit> hits;
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          collect_hits(scene, rays[i], hits);
                          counts[i] = uint32_t(hits.size());
                        }
                      });
  }

  void intersect_all(const RayInput& rays, uint32_t max_per_ray, HitLists& out) const override {
    RTCScene scene = query_scene();
    const size_t n = rays.size();
    std::vector<std::vector<Hit>> per_ray(n);
    out.truncated.assign(n, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kBlock),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          std::vector<Hit>& h = per_ray[i];
                          collect_hits(scene, rays[i], h);
                          std::sort(h.begin(), h.end(), hit_list_before);
                          if (h.size() > max_per_ray) {
                            out.truncated[i] = 1;
                            h.resize(max_per_ray);
                          }
                        }
                      });
    out.offsets.assign(n + 1, 0);
    for (size_t i = 0; i < n; ++i) out.offsets[i + 1] = out.offsets[i] + per_ray[i].size();
    out.hits.clear();
    out.hits.reserve(out.offsets[n]);
    for (const auto& h : per_ray) out.hits.insert(out.hits.end(), h.begin(), h.end());
  }

  void locate(std::span<const Vec3f> points, std::span<PointLocation> out) const override {
    if (out.size() < points.size())
      throw std::invalid_argument("locate: fewer result slots than points");
    RTCScene scene = query_scene();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), kBlock),
                      [&](const tbb::blocked_range<size_t>& range) {
                        std::vector<Hit> hits;
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          const Vec3f& p = points[i];
                          Ray r;
                          r.org = p;
                          r.dir = kInsideDirection;
                          r.tnear = 0.0f;
                          r.tfar = std::numeric_limits<float>::infinity();
                          if (!ray_valid(r)) {
                            out[i] = PointLocation::kOutside;
                          } else if (closest_one(p, 0.0f).found()) {
                            out[i] = PointLocation::kOnSurface;
                          } else {
                            collect_hits(scene, r, hits);
                            out[i] =
                                hits.size() % 2 ? PointLocation::kInside : PointLocation::kOutside;
                          }
                        }
                      });
  }

  void closest(std::span<const Vec3f> points, float max_distance,
               std::span<ClosestPoint> out) const override {
    if (out.size() < points.size())
      throw std::invalid_argument("closest: fewer result slots than points");
    if (!scene_) throw std::logic_error("embree: closest() before build()");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), kBlock),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i != range.end(); ++i)
                          out[i] = closest_one(points[i], max_distance);
                      });
  }

  BuildInfo info() const override { return info_; }

 private:
  // The state of one rtcPointQuery: the best triangle so far.
  struct ClosestQuery {
    const EmbreeIntersector* self;
    Vec3f p;
    double best_d2;
    uint32_t geom_id = kInvalidId, prim_id = kInvalidId;
    TrianglePoint at{};
  };

  // Embree's closest-point recipe (its closest_point tutorial): the callback
  // measures each triangle whose box is within the query radius and shrinks
  // the radius to the best distance so far.
  static bool closest_callback(RTCPointQueryFunctionArguments* args) {
    auto* q = static_cast<ClosestQuery*>(args->userPtr);
    const Geom& g = q->self->geoms_[args->geomID];
    const Vec3u& t = g.triangles[args->primID];
    const Vec3f &a = g.positions[t[0]], &b = g.positions[t[1]], &c = g.positions[t[2]];
    if (!is_finite(a) || !is_finite(b) || !is_finite(c) || !nonzero_area(a, b, c)) return false;
    const TrianglePoint tp = closest_point_on_triangle(q->p, a, b, c);
    if (!closest_before(tp.d2, args->geomID, args->primID, q->best_d2, q->geom_id, q->prim_id))
      return false;
    q->best_d2 = tp.d2;
    q->geom_id = args->geomID;
    q->prim_id = args->primID;
    q->at = tp;
    // Rounded up: a triangle at exactly this distance is still visited.
    args->query->radius =
        std::nextafter(float(std::sqrt(tp.d2)), std::numeric_limits<float>::infinity());
    return true;
  }

  ClosestPoint closest_one(const Vec3f& p, float max_distance) const {
    if (!is_finite(p) || std::fabs(p.x) > kRayComponentLimit ||
        std::fabs(p.y) > kRayComponentLimit || std::fabs(p.z) > kRayComponentLimit)
      return {};
    ClosestQuery q{this, p, closest_search_d2(max_distance)};
    RTCPointQuery query;
    query.x = p.x;
    query.y = p.y;
    query.z = p.z;
    query.time = 0.0f;
    query.radius = float(std::sqrt(q.best_d2));
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene_, &query, &context, closest_callback, &q);
    if (q.geom_id == kInvalidId) return {};
    return keep_within(to_closest_point(q.at, q.geom_id, q.prim_id), max_distance);
  }

  // The context the filter function sees: Embree passes &context, the first
  // member, so the filter can reach the hit list.
  struct CollectContext {
    RTCIntersectContext context;
    std::vector<Hit>* hits;
  };

  static void collect_filter(const RTCFilterFunctionNArguments* args) {
    auto* c = reinterpret_cast<CollectContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      c->hits->push_back(Hit{RTCRayN_tfar(args->ray, args->N, i), RTCHitN_u(args->hit, args->N, i),
                             RTCHitN_v(args->hit, args->N, i),
                             RTCHitN_geomID(args->hit, args->N, i),
                             RTCHitN_primID(args->hit, args->N, i)});
      args->valid[i] = 0;  // rejected: look further
    }
  }

  void collect_hits(RTCScene scene, const Ray& r, std::vector<Hit>& hits) const {
    hits.clear();
    if (!ray_valid(r)) return;
    CollectContext c;
    rtcInitIntersectContext(&c.context);
    c.context.filter = collect_filter;
    c.hits = &hits;
    RTCRayHit rh;
    to_embree(r, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &c.context, &rh);
  }

  // A second scene over the same geometries with context filter functions
  // enabled, made on the first count or all query: the flag stays off the
  // scene that intersect() and occluded() (and the benchmarks) use.
  RTCScene query_scene() const {
    if (!scene_) throw std::logic_error("embree: query before build()");
    std::lock_guard<std::mutex> lock(query_mutex_);
    if (query_scene_) return query_scene_;
    RTCScene q = rtcNewScene(device_.get());
    device_.check("rtcNewScene");
    rtcSetSceneFlags(
        q, RTCSceneFlags(rtcGetSceneFlags(scene_) | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
    rtcSetSceneBuildQuality(q, query_quality_);
    for (size_t i = 0; i < geoms_.size(); ++i)
      if (geoms_[i].geom) rtcAttachGeometryByID(q, geoms_[i].geom, unsigned(i));
    rtcCommitScene(q);
    device_.check("rtcCommitScene (query scene)");
    query_scene_ = q;
    return q;
  }

  void release_query_scene() {
    if (query_scene_) rtcReleaseScene(query_scene_);
    query_scene_ = nullptr;
  }

  struct Geom {
    RTCGeometry geom = nullptr;
    const Vec3f* positions = nullptr;  // what Embree reads (mesh array or `copy`)
    const Vec3u* triangles = nullptr;
    size_t vertex_count = 0;
    size_t triangle_count = 0;
    std::vector<Vec3f> copy;  // only for meshes not padded for Embree
  };

  bool coherent(const Ray* r) const { return rays_coherent(r, kPacket, coherent_origin_); }

  void intersect_one(RTCIntersectContext& context, const Ray& r, Hit& h) const {
    h = Hit{};
    if (!ray_valid(r)) return;
    RTCRayHit rh;
    to_embree(r, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return;
    h = Hit{rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.geomID, rh.hit.primID};
  }

  uint8_t occluded_one(RTCIntersectContext& context, const Ray& r) const {
    if (!ray_valid(r)) return 0;
    RTCRay er;
    to_embree(r, er);
    rtcOccluded1(scene_, &context, &er);
    return er.tfar == -std::numeric_limits<float>::infinity() ? 1 : 0;
  }

  static void to_packet(const Ray* r, RTCRay16& p) {
    for (size_t i = 0; i < kPacket; ++i) {
      p.org_x[i] = r[i].org.x;
      p.org_y[i] = r[i].org.y;
      p.org_z[i] = r[i].org.z;
      p.tnear[i] = r[i].tnear;
      p.dir_x[i] = r[i].dir.x;
      p.dir_y[i] = r[i].dir.y;
      p.dir_z[i] = r[i].dir.z;
      p.time[i] = 0.0f;
      p.tfar[i] = r[i].tfar;
      p.mask[i] = 0xFFFFFFFFu;
      p.id[i] = unsigned(i);
      p.flags[i] = 0;
    }
  }

  void intersect_packet(RTCIntersectContext& context, const Ray* r, Hit* h) const {
    alignas(64) int valid[kPacket];
    RTCRayHit16 p;
    to_packet(r, p.ray);
    for (size_t i = 0; i < kPacket; ++i) {
      valid[i] = -1;
      p.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      p.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
      p.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, scene_, &context, &p);
    for (size_t i = 0; i < kPacket; ++i)
      h[i] = p.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID
                 ? Hit{}
                 : Hit{p.ray.tfar[i], p.hit.u[i], p.hit.v[i], p.hit.geomID[i], p.hit.primID[i]};
  }

  void occluded_packet(RTCIntersectContext& context, const Ray* r, uint8_t* o) const {
    alignas(64) int valid[kPacket];
    RTCRay16 p;
    to_packet(r, p);
    for (size_t i = 0; i < kPacket; ++i) valid[i] = -1;
    rtcOccluded16(valid, scene_, &context, &p);
    for (size_t i = 0; i < kPacket; ++i)
      o[i] = p.tfar[i] == -std::numeric_limits<float>::infinity() ? 1 : 0;
  }

  static void check_indices(const TriangleMesh& m) {
    const size_t n = m.positions.size();
    for (size_t i = 0; i < m.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k)
        if (m.triangles[i][k] >= n)
          throw InputError(m.name, "triangle " + std::to_string(i) + " references vertex " +
                                       std::to_string(m.triangles[i][k]) + " of " +
                                       std::to_string(n));
  }

  bool same_layout(const Scene& scene) const {
    if (!scene_ || scene.meshes.size() != geoms_.size()) return false;
    for (size_t i = 0; i < geoms_.size(); ++i) {
      const TriangleMesh& m = scene.meshes[i];
      const Geom& g = geoms_[i];
      if (m.positions.size() != g.vertex_count || m.triangles.size() != g.triangle_count)
        return false;
      if (!g.geom) continue;
      if (m.triangles.data() != g.triangles) return false;
      if (g.copy.empty() && m.positions.data() != g.positions) return false;
      if (!g.copy.empty() && m.padded_for_embree()) return false;
    }
    return true;
  }

  void release_scene() {
    release_query_scene();
    for (Geom& g : geoms_)
      if (g.geom) rtcReleaseGeometry(g.geom);
    geoms_.clear();
    if (scene_) rtcReleaseScene(scene_);
    scene_ = nullptr;
  }

  void build_scene(const Scene& scene) {
    for (const TriangleMesh& m : scene.meshes) check_indices(m);
    release_scene();
    // Deformable scenes (Embree 3 scene.cpp, createTriangleAccel): only a scene
    // of build quality LOW gets the two-level structure whose per-geometry
    // BVHs honour the geometry build quality (REFIT: refit the first SAH tree
    // on every commit; LOW: Morton rebuild). So quality low or refit means
    // scene quality LOW + geometry quality low/refit; medium and high keep a
    // one-level BVH of that quality, rebuilt on every commit. An animated
    // scene, or quality low/refit, also gets RTC_SCENE_FLAG_DYNAMIC.
    const bool two_level = quality_ == RTC_BUILD_QUALITY_LOW || quality_ == RTC_BUILD_QUALITY_REFIT;
    const bool dynamic = two_level || scene.animation.animated();
    scene_ = rtcNewScene(device_.get());
    device_.check("rtcNewScene");
    int flags = RTC_SCENE_FLAG_NONE;
    if (options_.embree_robust) flags |= RTC_SCENE_FLAG_ROBUST;
    if (dynamic) flags |= RTC_SCENE_FLAG_DYNAMIC;
    rtcSetSceneFlags(scene_, RTCSceneFlags(flags));
    query_quality_ = two_level ? RTC_BUILD_QUALITY_LOW : quality_;
    rtcSetSceneBuildQuality(scene_, query_quality_);
    geoms_.resize(scene.meshes.size());
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
      const TriangleMesh& m = scene.meshes[i];
      Geom& g = geoms_[i];
      g.vertex_count = m.positions.size();
      g.triangle_count = m.triangles.size();
      if (m.triangles.empty() || m.positions.empty()) continue;  // nothing to hit
      g.triangles = m.triangles.data();
      if (m.padded_for_embree()) {
        g.positions = m.positions.data();
      } else {
        // Embree's 16-byte vertex loads read 4 bytes past the last vertex,
        // which this vector may not own (a Scene built without add_mesh):
        // keep one padded copy here instead of reading past the allocation.
        g.copy.reserve(m.positions.size() + 1);
        g.copy.assign(m.positions.begin(), m.positions.end());
        g.positions = g.copy.data();
      }
      g.geom = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
      device_.check("rtcNewGeometry");
      rtcSetSharedGeometryBuffer(g.geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, g.positions,
                                 0, sizeof(Vec3f), g.vertex_count);
      rtcSetSharedGeometryBuffer(g.geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, g.triangles, 0,
                                 sizeof(Vec3u), g.triangle_count);
      rtcSetGeometryBuildQuality(g.geom, quality_);
      rtcCommitGeometry(g.geom);
      rtcAttachGeometryByID(scene_, g.geom, unsigned(i));
      device_.check("triangle geometry");
    }
    rtcCommitScene(scene_);
    device_.check("rtcCommitScene");
    const AABB box = scene.bounds();
    coherent_origin_ = box.empty() ? 0.0f : kCoherentOriginFraction * max_component(box.diagonal());
  }

  BackendOptions options_;
  RTCBuildQuality quality_;
  EmbreeDevice device_;
  RTCScene scene_ = nullptr;
  RTCBuildQuality query_quality_ = RTC_BUILD_QUALITY_MEDIUM;  // the scene's build quality
  mutable std::mutex query_mutex_;
  mutable RTCScene query_scene_ = nullptr;
  std::vector<Geom> geoms_;
  float coherent_origin_ = 0.0f;  // see coherent()
  BuildInfo info_;
};

}  // namespace

std::unique_ptr<Intersector> make_embree_intersector(const BackendOptions& options) {
  return std::make_unique<EmbreeIntersector>(options);
}

}  // namespace hprt
