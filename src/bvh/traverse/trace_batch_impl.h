// The batch loop behind trace_batch.h, included only by the per-layout
// translation units (trace_batch_bvh2/4/8.cpp).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "bvh/intersect/ray_triangle.h"
#include "bvh/layout/bvh2.h"
#include "bvh/layout/wide_bvh.h"
#include "bvh/traverse/traverse_all.h"
#include "bvh/traverse/traverse_all_interleaved.h"
#include "bvh/traverse/traverse_bvh2.h"
#include "bvh/traverse/traverse_interleaved.h"
#include "bvh/traverse/traverse_packet.h"
#include "bvh/traverse/traverse_point.h"
#include "bvh/traverse/traverse_wide.h"
#include "core/aabb.h"
#include "core/hit_lists.h"
#include "core/ray_coherence.h"
#include "core/ray_input.h"

namespace hprt::detail {

inline constexpr size_t kRaysPerTask = 128;
inline constexpr size_t kRayGroup = 16;

template <typename Test, bool kAnyHit>
bool trace_one(const Bvh2& bvh, const Ray& ray, Hit& hit, ClosestHit* answer = nullptr) {
  return traverse<Test, kAnyHit>(bvh, ray, hit, nullptr, answer);
}
template <typename Test, bool kAnyHit, int N>
bool trace_one(const WideBvh<N>& bvh, const Ray& ray, Hit& hit, ClosestHit* answer = nullptr) {
  return traverse_wide<Test, kAnyHit>(bvh, ray, hit, nullptr, answer);
}

// How far apart a packet's origins may be: the embree backend's fraction of
// the scene's extent, with the root box in place of the scene's.
inline float packet_origin_tolerance(const AABB& root) {
  return root.empty() ? 0.0f : kCoherentOriginFraction * max_component(root.diagonal());
}
template <typename Bvh>
float packet_origin_tolerance(const Bvh& bvh) {
  if constexpr (std::is_same_v<Bvh, Bvh2>)
    return packet_origin_tolerance(bvh.bounds());
  else
    return packet_origin_tolerance(bvh.bounds);
}

// Whether a batch over `bvh` keeps several rays in flight per thread: wide
// trees of at least kInterleaveMinBytes (trace_batch.h).
template <typename Bvh>
bool interleaves(const Bvh& bvh) {
  if constexpr (std::is_same_v<Bvh, Bvh2>)
    return false;
  else
    return !bvh.empty() && bvh.memory_bytes() >= kInterleaveMinBytes;
}

// Rays [first, first + count) of a block one by one: any hit into
// occluded[i]; closest hits into hits[i], or `cols` when given. The hit ids
// of the group's closest hits are read once all its rays are traced, so the
// loads overlap, where each ray would otherwise end waiting for its own line.
template <typename Test, bool kAnyHit, typename Bvh>
void trace_singly(const Bvh& bvh, const Ray* rays, size_t first, size_t count, Hit* hits,
                  uint8_t* occluded, const HitColumnWriter* cols) {
  if constexpr (kAnyHit) {
    for (size_t i = first; i < first + count; ++i) {
      Hit h;
      occluded[i] = ray_is_valid(rays[i]) && trace_one<Test, true>(bvh, rays[i], h);
    }
  } else {
    ClosestHit answers[kRayGroup];
    for (size_t k = 0; k < count; ++k) {
      Hit unused;
      if (ray_is_valid(rays[first + k]))
        trace_one<Test, false>(bvh, rays[first + k], unused, &answers[k]);
    }
    for (size_t k = 0; k < count; ++k) {
      if (cols) {
        cols->write(answers[k], first + k);
      } else {
        Hit h;
        if (answers[k].found) answers[k].store(bvh.triangles, h);
        hits[first + k] = h;
      }
    }
  }
}

// kAnyHit writes `occluded`, otherwise `hits`, or `columns` instead when
// given (Intersector::intersect_columns). Each task takes its rays in blocks
// of kRayBlock (RayInput::block: six-float rays are converted there, into a
// buffer that stays in L1). In a tree of at least kInterleaveMinBytes the
// rays of a block that no packet takes are traced several at a time
// (traverse_interleaved.h); otherwise ray by ray.
template <typename Test, bool kAnyHit, typename Bvh>
void trace_batch(const Bvh& bvh, const RayInput& input, Hit* hits, uint8_t* occluded,
                 const HitColumnWriter* columns = nullptr) {
  constexpr bool kWide = !std::is_same_v<Bvh, Bvh2>;
  constexpr size_t kRayBlock = 256;
  constexpr size_t kGroupsPerBlock = kRayBlock / kRayGroup;
  [[maybe_unused]] const float tolerance = packet_origin_tolerance(bvh);
  const bool interleave = interleaves(bvh);
  const size_t n = input.size();
  const size_t groups = (n + kRayGroup - 1) / kRayGroup;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, groups, kRaysPerTask / kRayGroup),
      [&](const tbb::blocked_range<size_t>& range) {
        alignas(64) Ray buf[kRayBlock];
        size_t run[kRayBlock];  // indices into the block
        for (size_t g0 = range.begin(); g0 < range.end(); g0 += kGroupsPerBlock) {
          const size_t g1 = std::min(range.end(), g0 + kGroupsPerBlock);
          const size_t base = g0 * kRayGroup;
          const size_t size = std::min(g1 * kRayGroup, n) - base;
          const Ray* rays = input.block(base, size, buf);
          // Only the array this query writes is offset (the others are null).
          Hit* const block_hits = hits ? hits + base : nullptr;
          uint8_t* const block_occluded = occluded ? occluded + base : nullptr;
          const HitColumnWriter block_columns = columns ? columns->from(base) : HitColumnWriter{};
          const HitColumnWriter* const cols = columns ? &block_columns : nullptr;
          size_t run_size = 0;
          for (size_t first = 0; first < size; first += kRayGroup) {
            const size_t count = std::min(kRayGroup, size - first);
#if defined(HPRT_HAS_PACKETS)  // packets need AVX-512 (traverse_packet.h)
            static_assert(kRayGroup == kPacketSize);
            const Ray* r = rays + first;
            if (count == kRayGroup && rays_coherent(r, kRayGroup, tolerance)) {
              if constexpr (kAnyHit)
                traverse_packet<Test, true>(bvh, r, nullptr, block_occluded + first);
              else if (cols) {
                const HitColumnWriter lanes = cols->from(first);
                traverse_packet<Test, false>(bvh, r, nullptr, nullptr, &lanes);
              } else {
                traverse_packet<Test, false>(bvh, r, block_hits + first, nullptr);
              }
              continue;
            }
#endif
            if (interleave) {
              for (size_t i = first; i < first + count; ++i) run[run_size++] = i;
              continue;
            }
            trace_singly<Test, kAnyHit>(bvh, rays, first, count, block_hits, block_occluded, cols);
          }
          if constexpr (kWide)
            if (run_size)
              traverse_wide_interleaved<Test, kAnyHit>(bvh, rays, run, run_size, block_hits,
                                                       block_occluded, cols);
        }
      });
}

template <typename Bvh>
void intersect_batch_any_test(const Bvh& bvh, TriangleTestKind test, const RayInput& rays,
                              Hit* hits, const HitColumnWriter* columns) {
  if (test == TriangleTestKind::kMoller)
    trace_batch<MollerTest, false>(bvh, rays, hits, nullptr, columns);
  else
    trace_batch<WatertightTest, false>(bvh, rays, hits, nullptr, columns);
}

template <typename Bvh>
void occluded_batch_any_test(const Bvh& bvh, TriangleTestKind test, const RayInput& rays,
                             uint8_t* occluded) {
  if (test == TriangleTestKind::kMoller)
    trace_batch<MollerTest, true>(bvh, rays, nullptr, occluded);
  else
    trace_batch<WatertightTest, true>(bvh, rays, nullptr, occluded);
}

template <typename Test, typename Bvh>
void count_batch_test(const Bvh& bvh, const RayInput& rays, uint32_t* counts) {
  // In a wide tree of at least kInterleaveMinBytes, several rays in flight
  // per thread (traverse_all_interleaved.h), as trace_batch does.
  const bool interleave = interleaves(bvh);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, rays.size(), kRaysPerTask),
      [&](const tbb::blocked_range<size_t>& range) {
        if constexpr (!std::is_same_v<Bvh, Bvh2>)
          if (interleave) {
            std::fill(counts + range.begin(), counts + range.end(), 0u);
            // Records in one run over the whole range; six-float rays a
            // block of 256 at a time (RayInput::block), as trace_batch.
            constexpr size_t kBlock = 256;
            Ray buf[kBlock];
            const size_t block = rays.records() ? range.size() : kBlock;
            for (size_t base = range.begin(); base < range.end(); base += block) {
              const size_t size = std::min(block, range.end() - base);
              traverse_all_interleaved<Test>(bvh, rays.block(base, size, buf), 0, size,
                                             [&](size_t i, const LeafRange&, uint32_t,
                                                 const TriangleHit&) { ++counts[base + i]; });
            }
            return;
          }
        for (size_t i = range.begin(); i != range.end(); ++i) {
          const Ray ray = rays[i];
          uint32_t n = 0;
          if (ray_is_valid(ray))
            traverse_all<Test>(bvh, ray,
                               [&](const LeafRange&, uint32_t, const TriangleHit&) { ++n; });
          counts[i] = n;
        }
      });
}

// Per block of rays its hits, gathered into one array once every block's
// count is known.
template <typename Test, typename Bvh>
void all_batch_test(const Bvh& bvh, const RayInput& rays, uint32_t max_per_ray, HitLists& out) {
  const size_t n = rays.size();
  const size_t blocks = (n + kRaysPerTask - 1) / kRaysPerTask;
  std::vector<std::vector<Hit>> block_hits(blocks);
  std::vector<uint32_t> kept(n);
  out.truncated.assign(n, 0);
  const auto& refs = bvh.triangles.refs;
  // In a wide tree of at least kInterleaveMinBytes, a block's rays are
  // traced several at a time (traverse_all_interleaved.h), their hits
  // tagged with the ray and sorted by ray, then by hit_list_before.
  const bool interleave = interleaves(bvh);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    std::vector<Hit>& dst = block_hits[b];
    const size_t first = b * kRaysPerTask, end = std::min(n, first + kRaysPerTask);
    // Ray i's hits, in order: the nearest max_per_ray go to dst.
    const auto keep = [&](size_t i, const Hit* hits, size_t count) {
      if (count > max_per_ray) {
        out.truncated[i] = 1;
        count = max_per_ray;
      }
      kept[i] = uint32_t(count);
      dst.insert(dst.end(), hits, hits + count);
    };
    if constexpr (!std::is_same_v<Bvh, Bvh2>)
      if (interleave) {
        std::vector<std::pair<uint32_t, Hit>> tagged;
        Ray buf[kRaysPerTask];  // the block's rays as records (RayInput::block)
        traverse_all_interleaved<Test>(
            bvh, rays.block(first, end - first, buf), 0, end - first,
            [&](size_t i, const LeafRange&, uint32_t t, const TriangleHit& h) {
              tagged.emplace_back(uint32_t(i),
                                  Hit{h.t, h.u, h.v, refs[t].geom_id, refs[t].prim_id});
            });
        std::sort(tagged.begin(), tagged.end(), [](const auto& x, const auto& y) {
          return x.first != y.first ? x.first < y.first : hit_list_before(x.second, y.second);
        });
        std::vector<Hit> ray_hits;
        size_t j = 0;
        for (size_t i = first; i < end; ++i) {
          ray_hits.clear();
          for (; j < tagged.size() && tagged[j].first == i - first; ++j)
            ray_hits.push_back(tagged[j].second);
          keep(i, ray_hits.data(), ray_hits.size());
        }
        return;
      }
    std::vector<Hit> ray_hits;
    for (size_t i = first; i < end; ++i) {
      ray_hits.clear();
      const Ray ray = rays[i];
      if (ray_is_valid(ray))
        traverse_all<Test>(bvh, ray, [&](const LeafRange&, uint32_t t, const TriangleHit& h) {
          ray_hits.push_back(Hit{h.t, h.u, h.v, refs[t].geom_id, refs[t].prim_id});
        });
      std::sort(ray_hits.begin(), ray_hits.end(), hit_list_before);
      keep(i, ray_hits.data(), ray_hits.size());
    }
  });
  out.offsets.assign(n + 1, 0);
  for (size_t i = 0; i < n; ++i) out.offsets[i + 1] = out.offsets[i] + kept[i];
  out.hits.resize(out.offsets[n]);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    std::copy(block_hits[b].begin(), block_hits[b].end(),
              out.hits.begin() + std::ptrdiff_t(out.offsets[b * kRaysPerTask]));
  });
}

template <typename Bvh>
void count_batch_any_test(const Bvh& bvh, TriangleTestKind test, const RayInput& rays,
                          uint32_t* counts) {
  if (test == TriangleTestKind::kMoller)
    count_batch_test<MollerTest>(bvh, rays, counts);
  else
    count_batch_test<WatertightTest>(bvh, rays, counts);
}

template <typename Bvh>
void all_batch_any_test(const Bvh& bvh, TriangleTestKind test, const RayInput& rays,
                        uint32_t max_per_ray, HitLists& out) {
  if (test == TriangleTestKind::kMoller)
    all_batch_test<MollerTest>(bvh, rays, max_per_ray, out);
  else
    all_batch_test<WatertightTest>(bvh, rays, max_per_ray, out);
}

inline bool point_valid(const Vec3f& p) {
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(p[a]) <= kRayComponentLimit)) return false;
  return true;
}

// In a wide tree of at least kInterleaveMinBytes, the rays of the points
// that are not on the surface are traced several at a time
// (traverse_all_interleaved.h), kRaysPerTask points at a time.
template <int N>
void locate_interleaved(const WideBvh<N>& bvh, std::span<const Vec3f> points, size_t begin,
                        size_t end, PointLocation* out) {
  Ray rays[kRaysPerTask];
  unsigned crossings[kRaysPerTask];
  for (size_t b = begin; b < end; b += kRaysPerTask) {
    const size_t n = std::min(kRaysPerTask, end - b);
    for (size_t k = 0; k < n; ++k) {
      const Vec3f& p = points[b + k];
      crossings[k] = 0;
      rays[k] = detail::inside_ray(p);
      if (point_valid(p) && !point_on_surface(bvh, p)) continue;
      out[b + k] = point_valid(p) ? PointLocation::kOnSurface : PointLocation::kOutside;
      rays[k].dir = Vec3f(0.0f);  // an invalid ray: not traced
    }
    traverse_all_interleaved<WatertightTest>(
        bvh, rays, 0, n,
        [&](size_t k, const LeafRange& leaf, uint32_t i, const TriangleHit&) {
          crossings[k] += detail::crosses_ahead(bvh.triangles, leaf, i, points[b + k]);
        },
        detail::kInsideLeafTnear);
    for (size_t k = 0; k < n; ++k)
      if (ray_is_valid(rays[k]))
        out[b + k] = crossings[k] % 2 ? PointLocation::kInside : PointLocation::kOutside;
  }
}

template <typename Bvh>
void locate_batch_impl(const Bvh& bvh, std::span<const Vec3f> points, PointLocation* out) {
  const bool interleave = interleaves(bvh);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), kRaysPerTask),
                    [&](const tbb::blocked_range<size_t>& range) {
                      if constexpr (!std::is_same_v<Bvh, Bvh2>)
                        if (interleave) {
                          locate_interleaved(bvh, points, range.begin(), range.end(), out);
                          return;
                        }
                      for (size_t i = range.begin(); i != range.end(); ++i)
                        out[i] = point_valid(points[i]) ? locate_point(bvh, points[i])
                                                        : PointLocation::kOutside;
                    });
}

template <typename Bvh>
void closest_batch_impl(const Bvh& bvh, std::span<const Vec3f> points, float max_distance,
                        ClosestPoint* out) {
  const double max_d2 = closest_search_d2(max_distance);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), kRaysPerTask),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i != range.end(); ++i)
                        out[i] =
                            point_valid(points[i])
                                ? keep_within(closest_point(bvh, points[i], max_d2), max_distance)
                                : ClosestPoint{};
                    });
}

}  // namespace hprt::detail
