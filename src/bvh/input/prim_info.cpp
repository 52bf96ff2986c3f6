// make_prim_info: one box and one centroid (the box centre, as in Wald 2007
// and Embree) per valid triangle, in (geomID, primID) order. Large meshes are
// processed in parallel over fixed-size chunks (fill, then close the gaps
// invalid triangles left), so the result never depends on the thread count.
#include "bvh/input/prim_info.h"
#include "bvh/input/prim_info_lanes.h"
#include "bvh/memory/huge_buffer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>

namespace hprt {

namespace {

constexpr size_t kChunk = 16384;

}  // namespace

PrimInfo make_prim_info(const Scene& scene, bool store_centroids) {
  PrimInfo info;
  struct Chunk {
    uint32_t geom;
    size_t begin, end;  // triangles of mesh `geom`
    size_t slot;        // where the chunk's first triangle goes if all are valid
    size_t valid = 0;
  };
  std::vector<Chunk> chunks;
  size_t all = 0;
  for (size_t g = 0; g < scene.meshes.size(); ++g) {
    const size_t n = scene.meshes[g].triangle_count();
    for (size_t b = 0; b < n; b += kChunk)
      chunks.push_back({static_cast<uint32_t>(g), b, std::min(n, b + kChunk), all + b});
    all += n;
  }
  // Uninitialised: the fill writes every element kept (first touch in parallel).
  info.bounds = BuildArray<AABB>(all);
  if (store_centroids) info.centroids = BuildArray<Vec3f>(all);
  info.refs = BuildArray<PrimRef>(all);
  // One pass: each chunk writes its valid triangles from its slot on, and
  // reduces its bounds (min/max: exact in any order).
  std::vector<AABB> chunk_bounds(chunks.size()), chunk_cbounds(chunks.size());
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t c) {
    Chunk& ch = chunks[c];
    const TriangleMesh& m = scene.meshes[ch.geom];
    const auto fill_one = [&](size_t i, size_t& w, AABB& sb, AABB& cb) {
      if (!m.triangle_valid(i)) return;
      const AABB b = triangle_box(m, i);
      const Vec3f centre = b.center();
      info.bounds[w] = b;
      if (store_centroids) info.centroids[w] = centre;
      info.refs[w] = {ch.geom, static_cast<uint32_t>(i)};
      sb.extend(b);
      cb.extend(centre);
      ++w;
    };
    size_t w = ch.slot;
    AABB sb, cb;
    size_t i = ch.begin;
#if defined(HPRT_HAS_PRIM_INFO_LANES)
    if (prim_info_lanes_fit(m)) {
      // 16 at a time while all 16 are valid, else one step of the loop below.
      PrimInfoLanesBounds lanes;
      bool any = false;
      while (i + 16 <= ch.end) {
        Vec3f* const centroids = store_centroids ? &info.centroids[w] : nullptr;
        if (fill_prim_info_16(m, ch.geom, i, &info.bounds[w], centroids, &info.refs[w], lanes)) {
          i += 16, w += 16, any = true;
          continue;
        }
        for (const size_t e = i + 16; i < e; ++i) fill_one(i, w, sb, cb);
      }
      if (any) lanes.reduce_into(sb, cb);
    }
#endif
    for (; i < ch.end; ++i) fill_one(i, w, sb, cb);
    ch.valid = w - ch.slot;
    chunk_bounds[c] = sb;
    chunk_cbounds[c] = cb;
  });
  // Invalid triangles (rare) leave gaps: close them, chunk by chunk in order
  // (a chunk only moves down, onto slots already emptied).
  size_t total = 0;
  for (const Chunk& ch : chunks) {
    if (total != ch.slot) {
      const auto move_down = [&](auto& a) {
        std::copy(a.begin() + ch.slot, a.begin() + ch.slot + ch.valid, a.begin() + total);
      };
      move_down(info.bounds);
      if (store_centroids) move_down(info.centroids);
      move_down(info.refs);
    }
    total += ch.valid;
  }
  info.invalid = all - total;
  info.bounds.shrink(total);
  if (store_centroids) info.centroids.shrink(total);
  info.refs.shrink(total);
  for (size_t c = 0; c < chunks.size(); ++c) {
    info.scene_bounds.extend(chunk_bounds[c]);
    info.centroid_bounds.extend(chunk_cbounds[c]);
  }
  return info;
}

}  // namespace hprt
