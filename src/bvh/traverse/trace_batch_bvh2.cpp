// trace_batch.h for the bvh2 layout: both triangle tests, closest and any hit.
#include "bvh/traverse/trace_batch.h"
#include "bvh/traverse/trace_batch_impl.h"

namespace hprt {

void intersect_batch(const Bvh2& bvh, TriangleTestKind test, std::span<const Ray> rays, Hit* hits) {
  detail::intersect_batch_any_test(bvh, test, rays, hits);
}

void occluded_batch(const Bvh2& bvh, TriangleTestKind test, std::span<const Ray> rays,
                    uint8_t* occluded) {
  detail::occluded_batch_any_test(bvh, test, rays, occluded);
}

}  // namespace hprt
