// Closest-hit and any-hit traversal of incoherent rays of the wide layout,
// several rays in flight per thread. A single ray's traversal waits on every
// node it enters (a node is four cache lines, and on a mesh larger than the
// caches most of them come from memory); here K rays take turns, one node
// or leaf each, and each requests the lines of the node it will enter next
// before handing over, so the other rays' work hides that load. Each ray
// visits the same nodes in the same order as traverse_wide (the node visit
// and pop are traverse_wide.h's), so the answers are bit-identical.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "bvh/traverse/traverse_wide.h"

namespace hprt {

namespace detail {

// Rays in flight per thread: enough turns of work to cover a load from memory.
inline constexpr int kRaysInFlight = 8;

template <typename Test, int N>
struct RayInFlight {
  RayInFlight() : slab(Ray{}) {}
  // Made in place (std::construct_at) for each ray: built aside and copied,
  // the slab and test data are a store-forwarding stall per ray. The stack
  // is left uninitialised.
  RayInFlight(const Ray& r, size_t index, NodeRef root, const AABB& bounds)
      : slab(r),
        prep(Test::prepare(r, bounds)),
        tnear(r.tnear),
        tfar(r.tfar),
        cur(root),
        sp(0),
        ray(index) {}

  WideSlabRay slab;
  typename Test::Prepared prep;
  float tnear, tfar;
  ClosestHit closest;
  NodeRef cur;  // what the ray enters on its next turn
  int sp;
  size_t ray;  // index into the batch
  WideStackEntry stack[kWideStackSize<N>];
};

template <typename Test, int N>
HPRT_FORCE_INLINE void prefetch_ref(const WideBvh<N>& bvh, NodeRef r) {
  if (r.is_leaf())
    Test::prefetch(bvh.triangles, r.leaf_range());
  else
    prefetch_node(&bvh.nodes[r.index()]);
}

// One turn of ray s: its current node or leaf. Returns true when the ray is
// done (an any-hit found, or nothing left to pop); otherwise s.cur is the
// next node or leaf, its lines requested.
template <typename Test, bool kAnyHit, int N>
HPRT_FORCE_INLINE bool take_turn(const WideBvh<N>& bvh, RayInFlight<Test, N>& s) {
  if (s.cur.is_inner()) {
    s.cur = visit_wide_node<Test, kAnyHit, false>(bvh, bvh.nodes[s.cur.index()], s.slab, s.tnear,
                                                  s.tfar, s.stack, s.sp);
    if (!s.cur.empty()) {
      prefetch_ref<Test>(bvh, s.cur);
      return false;
    }
  } else if (intersect_leaf<Test, kAnyHit, false>(s.prep, bvh.triangles, s.cur.leaf_range(),
                                                  s.tnear, s.tfar, s.closest, nullptr)) {
    return true;
  }
  s.cur = pop_closer(s.stack, s.sp, s.tfar);
  if (s.cur.empty()) return true;
  prefetch_ref<Test>(bvh, s.cur);
  return false;
}

}  // namespace detail

// Traces rays[order[k]] for k in [0, count) (valid or not: an invalid ray
// misses), writing hits[i] (closest hit) or occluded[i] (kAnyHit) for each
// such i, up to kRaysInFlight at a time; with `columns` the closest hits go
// there instead of `hits`. The tree must not be empty.
template <typename Test, bool kAnyHit, int N>
void traverse_wide_interleaved(const WideBvh<N>& bvh, const Ray* rays, const size_t* order,
                               size_t count, Hit* hits, uint8_t* occluded,
                               const HitColumnWriter* columns = nullptr) {
  constexpr int K = detail::kRaysInFlight;
  detail::RayInFlight<Test, N> slot[K];
  bool live[K] = {};
  size_t next = 0;
  // Starts the next valid ray in slot s (invalid ones miss on the way);
  // false when none is left.
  const auto start = [&](detail::RayInFlight<Test, N>& s) {
    for (; next < count; ++next) {
      const size_t i = order[next];
      const Ray& r = rays[i];
      if (!ray_is_valid(r)) {
        if constexpr (kAnyHit) {
          occluded[i] = 0;
        } else if (columns) {
          columns->out.write_miss(i);
        } else {
          hits[i] = Hit{};
        }
        continue;
      }
      std::construct_at(&s, r, i, bvh.root, bvh.bounds);
      ++next;
      return true;
    }
    return false;
  };
  const auto finish = [&](const detail::RayInFlight<Test, N>& s) {
    if constexpr (kAnyHit) {
      occluded[s.ray] = s.closest.found;
    } else if (columns) {
      columns->write(s.closest, s.ray);
    } else {
      Hit h;
      if (s.closest.found) s.closest.store(bvh.triangles, h);
      hits[s.ray] = h;
    }
  };
  // A closest hit's ids (and normal) are read a turn after the ray ends,
  // their lines requested when it ended (done[k]).
  bool done[K] = {};
  int in_flight = 0;
  for (int k = 0; k < K; ++k) in_flight += (live[k] = start(slot[k]));
  while (in_flight > 0) {
    for (int k = 0; k < K; ++k) {
      if (!live[k]) continue;
      if (!done[k]) {
        if (!detail::take_turn<Test, kAnyHit>(bvh, slot[k])) continue;
        if constexpr (!kAnyHit)
          if (slot[k].closest.found) {
            __builtin_prefetch(&bvh.triangles.refs[slot[k].closest.index]);
            if (columns) columns->prefetch(slot[k].closest);
            done[k] = true;
            continue;
          }
      }
      done[k] = false;
      finish(slot[k]);
      if (!(live[k] = start(slot[k]))) --in_flight;
    }
  }
}

}  // namespace hprt
