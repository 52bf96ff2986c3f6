#include <cstring>
#include <stdexcept>
#include <string>

#include "api/api_errors.h"
#include "api/api_scene.h"
#include "backends/backend_option_parse.h"
#include "core/parallel.h"

namespace hprt::api {

static_assert(kMaxThreads == hprt::kMaxThreads);

const Intersector& Backend::Impl::built() const {
  if (!intersector) throw std::invalid_argument("backend used after being moved from");
  return *intersector;
}

Backend::Backend(const std::string& name, const Options& options)
    : impl_(std::make_unique<Impl>()) {
  translate_errors([&] {
    BackendOptions& o = impl_->options;
    o.backend = name;
    bool threads_given = false;
    for (const auto& [key, value] : options) {
      set_backend_option(o, key, value);
      threads_given = threads_given || key == "threads";
    }
    if (threads_given)
      impl_->arena = std::make_unique<tbb::task_arena>(
          o.threads > 0 ? o.threads : int(tbb::task_arena::automatic));
    impl_->intersector = impl_->run([&] { return make_intersector(name, o); });
  });
}

Backend::~Backend() = default;
Backend::Backend(Backend&&) noexcept = default;
Backend& Backend::operator=(Backend&&) noexcept = default;

void Backend::build(const Scene& scene) {
  translate_errors([&] {
    impl_->run([&] { const_cast<Intersector&>(impl_->built()).build(scene.impl().scene); });
    impl_->scene = &scene.impl().scene;
  });
}

void Backend::update(const Scene& scene) {
  translate_errors([&] {
    impl_->run([&] { const_cast<Intersector&>(impl_->built()).update(scene.impl().scene); });
    impl_->scene = &scene.impl().scene;
  });
}

// The public records are hprt's own (static_asserts in backends/plugin_backend.cpp).
void Backend::intersect(std::span<const Ray> rays, std::span<Hit> hits) const {
  if (hits.size() < rays.size()) throw std::invalid_argument("intersect: fewer hits than rays");
  const std::span<const hprt::Ray> r(reinterpret_cast<const hprt::Ray*>(rays.data()), rays.size());
  const std::span<hprt::Hit> h(reinterpret_cast<hprt::Hit*>(hits.data()), rays.size());
  translate_errors([&] { impl_->run([&] { impl_->built().intersect(r, h); }); });
}

namespace {

// The columns a batch of n rays writes, each checked to hold n entries.
hprt::HitColumns checked_columns(const HitColumns& out, size_t n) {
  const auto column = [n](auto span, size_t per_ray, const char* name) {
    if (!span.empty() && span.size() < per_ray * n)
      throw std::invalid_argument(std::string("intersect: column ") + name + " holds fewer than " +
                                  std::to_string(per_ray) + " per ray");
    return span.empty() ? nullptr : span.data();
  };
  return {column(out.t, 1, "t"), column(out.geom_id, 1, "geom_id"),
          column(out.prim_id, 1, "prim_id"), column(out.uv, 2, "uv"),
          column(out.normal, 3, "normal")};
}

void intersect_columns(const Backend::Impl& impl, const hprt::RayInput& rays,
                       const hprt::HitColumns& columns) {
  static const hprt::Scene kNothingBuilt;
  const hprt::Scene& scene = impl.scene ? *impl.scene : kNothingBuilt;
  translate_errors(
      [&] { impl.run([&] { impl.built().intersect_columns(scene, rays, columns); }); });
}

}  // namespace

void Backend::intersect(std::span<const Ray> rays, const HitColumns& out) const {
  const std::span<const hprt::Ray> r(reinterpret_cast<const hprt::Ray*>(rays.data()), rays.size());
  intersect_columns(*impl_, r, checked_columns(out, rays.size()));
}

void Backend::intersect(const RayArray& rays, const HitColumns& out) const {
  const hprt::RayInput r(rays.rays, rays.tnear, rays.tfar);  // checks 6 floats per ray
  intersect_columns(*impl_, r, checked_columns(out, r.size()));
}

namespace {

void occluded_of(const Backend::Impl& impl, const hprt::RayInput& rays,
                 std::span<uint8_t> occluded) {
  if (occluded.size() < rays.size())
    throw std::invalid_argument("occluded: fewer results than rays");
  translate_errors(
      [&] { impl.run([&] { impl.built().occluded(rays, occluded.first(rays.size())); }); });
}

}  // namespace

void Backend::occluded(std::span<const Ray> rays, std::span<uint8_t> occluded) const {
  occluded_of(
      *impl_,
      std::span<const hprt::Ray>(reinterpret_cast<const hprt::Ray*>(rays.data()), rays.size()),
      occluded);
}

void Backend::occluded(const RayArray& rays, std::span<uint8_t> occluded) const {
  occluded_of(*impl_, hprt::RayInput(rays.rays, rays.tnear, rays.tfar), occluded);
}

namespace {

hprt::RayInput records_of(std::span<const Ray> rays) {
  return std::span<const hprt::Ray>(reinterpret_cast<const hprt::Ray*>(rays.data()), rays.size());
}

void count_of(const Backend::Impl& impl, const hprt::RayInput& rays, std::span<uint32_t> counts) {
  if (counts.size() < rays.size()) throw std::invalid_argument("count: fewer results than rays");
  translate_errors([&] { impl.run([&] { impl.built().count(rays, counts.first(rays.size())); }); });
}

Backend::HitLists intersect_all_of(const Backend::Impl& impl, const hprt::RayInput& rays,
                                   uint32_t max_per_ray) {
  hprt::HitLists lists;
  translate_errors(
      [&] { impl.run([&] { impl.built().intersect_all(rays, max_per_ray, lists); }); });
  Backend::HitLists out;
  out.offsets = std::move(lists.offsets);
  out.truncated = std::move(lists.truncated);
  out.hits.resize(lists.hits.size());
  std::memcpy(out.hits.data(), lists.hits.data(), lists.hits.size() * sizeof(Hit));
  return out;
}

}  // namespace

void Backend::count(std::span<const Ray> rays, std::span<uint32_t> counts) const {
  count_of(*impl_, records_of(rays), counts);
}

void Backend::count(const RayArray& rays, std::span<uint32_t> counts) const {
  count_of(*impl_, hprt::RayInput(rays.rays, rays.tnear, rays.tfar), counts);
}

Backend::HitLists Backend::intersect_all(std::span<const Ray> rays, uint32_t max_per_ray) const {
  return intersect_all_of(*impl_, records_of(rays), max_per_ray);
}

Backend::HitLists Backend::intersect_all(const RayArray& rays, uint32_t max_per_ray) const {
  return intersect_all_of(*impl_, hprt::RayInput(rays.rays, rays.tnear, rays.tfar), max_per_ray);
}

namespace {
std::span<const Vec3f> as_points(std::span<const float> xyz, const char* query) {
  if (xyz.size() % 3 != 0)
    throw std::invalid_argument(std::string(query) + ": points must hold 3 floats per point, got " +
                                std::to_string(xyz.size()));
  return {reinterpret_cast<const Vec3f*>(xyz.data()), xyz.size() / 3};
}
}  // namespace

void Backend::inside(std::span<const float> points, std::span<uint8_t> locations) const {
  const std::span<const Vec3f> p = as_points(points, "inside");
  if (locations.size() < p.size()) throw std::invalid_argument("inside: fewer results than points");
  static_assert(sizeof(PointLocation) == 1);
  const std::span<PointLocation> out(reinterpret_cast<PointLocation*>(locations.data()), p.size());
  translate_errors([&] { impl_->run([&] { impl_->built().locate(p, out); }); });
}

void Backend::closest(std::span<const float> points, std::span<ClosestPoint> closest,
                      float max_distance) const {
  const std::span<const Vec3f> p = as_points(points, "closest");
  if (closest.size() < p.size()) throw std::invalid_argument("closest: fewer results than points");
  if (!(max_distance >= 0.0f))
    throw Error("max_distance: must be >= 0, got " + std::to_string(max_distance));
  static_assert(sizeof(ClosestPoint) == sizeof(hprt::ClosestPoint));
  const std::span<hprt::ClosestPoint> out(reinterpret_cast<hprt::ClosestPoint*>(closest.data()),
                                          p.size());
  translate_errors([&] { impl_->run([&] { impl_->built().closest(p, max_distance, out); }); });
}

BackendInfo Backend::info() const {
  const BuildInfo i = impl_->built().info();
  return {i.name, i.build_ms, i.memory_bytes, i.rebuilt, i.malformed_answers};
}

}  // namespace hprt::api
