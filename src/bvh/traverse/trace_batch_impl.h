// The batch loop behind trace_batch.h, included only by the per-layout
// translation units (trace_batch_bvh2/4/8.cpp).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "bvh/intersect/ray_triangle.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/traverse_bvh2.h"
#include "bvh/traverse/traverse_packet.h"
#include "bvh/traverse/traverse_wide.h"
#include "core/aabb.h"
#include "core/ray_coherence.h"

namespace hprt::detail {

inline constexpr size_t kRaysPerTask = 128;
inline constexpr size_t kRayGroup = 16;

template <typename Test, bool kAnyHit>
bool trace_one(const Bvh2& bvh, const Ray& ray, Hit& hit) {
  return traverse<Test, kAnyHit>(bvh, ray, hit);
}
template <typename Test, bool kAnyHit, int N>
bool trace_one(const WideBvh<N>& bvh, const Ray& ray, Hit& hit) {
  return traverse_wide<Test, kAnyHit>(bvh, ray, hit);
}

// Packets need AVX-512 (traverse_packet.h).
#if defined(HPRT_HAS_PACKETS)
inline constexpr bool kTracesPackets = true;
#else
inline constexpr bool kTracesPackets = false;
#endif

// How far apart a packet's origins may be: the embree backend's fraction of
// the scene's extent, with the root box in place of the scene's.
inline float packet_origin_tolerance(const AABB& root) {
  return root.empty() ? 0.0f : kCoherentOriginFraction * max_component(root.diagonal());
}
inline float packet_origin_tolerance(const Bvh2& bvh) {
  return bvh.empty() ? 0.0f : packet_origin_tolerance(AABB(bvh.nodes[0].min, bvh.nodes[0].max));
}
template <int N>
float packet_origin_tolerance(const WideBvh<N>& bvh) {
  if (!bvh.root.is_inner()) return 0.0f;
  const WideNode<N>& root = bvh.nodes[bvh.root.index()];
  AABB box;
  for (int i = 0; i < N && !root.child[i].empty(); ++i) box.extend(root.box(i));
  return packet_origin_tolerance(box);
}

// kAnyHit writes `occluded`, otherwise `hits`.
template <typename Test, bool kAnyHit, typename Bvh>
void trace_batch(const Bvh& bvh, std::span<const Ray> rays, Hit* hits, uint8_t* occluded) {
  const float tolerance = packet_origin_tolerance(bvh);
  const size_t groups = (rays.size() + kRayGroup - 1) / kRayGroup;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, groups, kRaysPerTask / kRayGroup),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t g = range.begin(); g != range.end(); ++g) {
                        const size_t first = g * kRayGroup;
                        const size_t count = std::min(kRayGroup, rays.size() - first);
                        const Ray* r = rays.data() + first;
                        if constexpr (kTracesPackets) {
                          static_assert(kRayGroup == kPacketSize);
                          if (count == kRayGroup && rays_coherent(r, kRayGroup, tolerance)) {
                            // Only the array this query writes is offset (the other is null).
                            if constexpr (kAnyHit)
                              traverse_packet<Test, true>(bvh, r, nullptr, occluded + first);
                            else
                              traverse_packet<Test, false>(bvh, r, hits + first, nullptr);
                            continue;
                          }
                        }
                        for (size_t i = first; i < first + count; ++i) {
                          Hit h;
                          const bool found =
                              ray_is_valid(rays[i]) && trace_one<Test, kAnyHit>(bvh, rays[i], h);
                          if constexpr (kAnyHit)
                            occluded[i] = found;
                          else
                            hits[i] = h;
                        }
                      }
                    });
}

template <typename Bvh>
void intersect_batch_any_test(const Bvh& bvh, TriangleTestKind test, std::span<const Ray> rays,
                              Hit* hits) {
  if (test == TriangleTestKind::kMoller)
    trace_batch<MollerTest, false>(bvh, rays, hits, nullptr);
  else
    trace_batch<WatertightTest, false>(bvh, rays, hits, nullptr);
}

template <typename Bvh>
void occluded_batch_any_test(const Bvh& bvh, TriangleTestKind test, std::span<const Ray> rays,
                             uint8_t* occluded) {
  if (test == TriangleTestKind::kMoller)
    trace_batch<MollerTest, true>(bvh, rays, nullptr, occluded);
  else
    trace_batch<WatertightTest, true>(bvh, rays, nullptr, occluded);
}

}  // namespace hprt::detail
