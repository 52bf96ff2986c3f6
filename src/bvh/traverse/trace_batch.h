// A batch of rays through one layout of the bvh: the entry points the bvh
// backend calls once per batch. Rays go in fixed groups of 16 (ray i in
// group i / 16, whatever the thread count), the groups in parallel
// (oneTBB, in the caller's task arena). With AVX-512 a full group of
// coherent rays (core/ray_coherence.h) is one packet, answered bit for bit as
// its rays one by one; the other rays of a wide layout are traced several at
// a time per thread (traverse_interleaved.h), the binary layout's ray by ray,
// each with the single ray's answer. Invalid rays miss.
// One translation unit per layout instantiates them (trace_batch_bvh*.cpp),
// as Embree compiles one per width.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "bvh/input/build_options.h"
#include "bvh/intersect/leaf_intersect.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "core/hit.h"
#include "core/hit_lists.h"
#include "core/point_query.h"
#include "core/ray.h"
#include "core/ray_input.h"

namespace hprt {

// Trees from this size on (about 250k triangles) are traced several rays at
// a time: most of their nodes come from memory, a wait that the other rays'
// work hides. A smaller tree stays in the caches, where the interleaving
// mostly adds its bookkeeping to each ray (docs/ARCHITECTURE.md section 3).
inline constexpr size_t kInterleaveMinBytes = size_t{16} << 20;

// Closest hits: hits[i] for rays[i] (hits has at least rays.size() slots),
// or with `columns` written there instead (hits unused: null).
void intersect_batch(const Bvh2& bvh, TriangleTestKind test, const RayInput& rays, Hit* hits,
                     const HitColumnWriter* columns = nullptr);
void intersect_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays, Hit* hits,
                     const HitColumnWriter* columns = nullptr);
void intersect_batch(const WideBvh<8>& bvh, TriangleTestKind test, const RayInput& rays, Hit* hits,
                     const HitColumnWriter* columns = nullptr);

// Any hit: occluded[i] = 1 when rays[i] hits something in its interval, else 0.
void occluded_batch(const Bvh2& bvh, TriangleTestKind test, const RayInput& rays,
                    uint8_t* occluded);
void occluded_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays,
                    uint8_t* occluded);
void occluded_batch(const WideBvh<8>& bvh, TriangleTestKind test, const RayInput& rays,
                    uint8_t* occluded);

// Crossings: counts[i] = how many triangles rays[i] hits in (tnear, tfar],
// each crossing of a surface once (the watertight test's fill rule).
void count_batch(const Bvh2& bvh, TriangleTestKind test, const RayInput& rays, uint32_t* counts);
void count_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays,
                 uint32_t* counts);
void count_batch(const WideBvh<8>& bvh, TriangleTestKind test, const RayInput& rays,
                 uint32_t* counts);

// Every hit of each ray in (tnear, tfar], the nearest max_per_ray kept
// (core/hit_lists.h: order and the truncated flags).
void all_batch(const Bvh2& bvh, TriangleTestKind test, const RayInput& rays, uint32_t max_per_ray,
               HitLists& out);
void all_batch(const WideBvh<4>& bvh, TriangleTestKind test, const RayInput& rays,
               uint32_t max_per_ray, HitLists& out);
void all_batch(const WideBvh<8>& bvh, TriangleTestKind test, const RayInput& rays,
               uint32_t max_per_ray, HitLists& out);

// The point queries (core/point_query.h); they read the watertight test's
// vertex arrays, so the tree must hold them (TriangleArrays::kVerts). A point
// that is not a valid ray origin (a non-finite coordinate or one beyond
// 1.844e18) is outside and has no closest point.
void locate_batch(const Bvh2& bvh, std::span<const Vec3f> points, PointLocation* out);
void locate_batch(const WideBvh<4>& bvh, std::span<const Vec3f> points, PointLocation* out);
void locate_batch(const WideBvh<8>& bvh, std::span<const Vec3f> points, PointLocation* out);
// Within max_distance (inclusive; +inf for no bound).
void closest_batch(const Bvh2& bvh, std::span<const Vec3f> points, float max_distance,
                   ClosestPoint* out);
void closest_batch(const WideBvh<4>& bvh, std::span<const Vec3f> points, float max_distance,
                   ClosestPoint* out);
void closest_batch(const WideBvh<8>& bvh, std::span<const Vec3f> points, float max_distance,
                   ClosestPoint* out);

}  // namespace hprt
