// trace_batch.h for the bvh4 layout: both triangle tests, closest hit, any hit, counts, all
// hits and the point queries.
#include "bvh/traverse/trace_batch.h"
#include "bvh/traverse/trace_batch_impl.h"

namespace hprt {

void intersect_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays, Hit* hits,
                     const HitColumnWriter* columns) {
  detail::intersect_batch_any_test(bvh, test, rays, hits, columns);
}

void occluded_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays,
                    uint8_t* occluded) {
  detail::occluded_batch_any_test(bvh, test, rays, occluded);
}

void count_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays,
                 uint32_t* counts) {
  detail::count_batch_any_test(bvh, test, rays, counts);
}

void all_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays,
               uint32_t max_per_ray, HitLists& out) {
  detail::all_batch_any_test(bvh, test, rays, max_per_ray, out);
}

void locate_batch(const WideBvh<4>& bvh, std::span<const Vec3f> points, PointLocation* out) {
  detail::locate_batch_impl(bvh, points, out);
}

void closest_batch(const WideBvh<4>& bvh, std::span<const Vec3f> points, float max_distance,
                   ClosestPoint* out) {
  detail::closest_batch_impl(bvh, points, max_distance, out);
}

}  // namespace hprt
