// Packet traversal of every layout (binary, 4- and 8-wide) for coherent rays
// (camera rays, and the shadow and mirror rays of neighbouring pixels): 16
// rays go down the tree together, one AVX-512 lane per ray, so each node is
// fetched once for all of them and each of its child boxes is tested against
// the 16 rays in one pass (Wald, Slusallek, Benthin & Wagner, "Interactive
// Rendering with Coherent Ray Tracing", EG 2001; Embree's rtcIntersect16).
// The loop is written once: RayPacket (ray_packet.h) holds the lanes and
// tests them against a box, PacketNodes<Bvh> (packet_nodes.h) gives a layout's
// root and children (as NodeRefs) and their boxes, culling a wide node's
// children against the packet's frustum first.
//
// Per lane, every operation is the single-ray one: the child box test is
// slab_robust()'s (the lane's own octant picks the near and far planes, each
// with its padded reciprocal, NaN slab values dropped) and the
// leaf runs the same triangle test with the lane's own Prepared state and
// interval. Children are entered nearest first by their smallest entry
// distance over the packet's lanes; a stack entry keeps every lane's entry
// distance, so a popped node only goes on with the lanes whose closest hit is
// not already nearer. Lanes take part in a node only if their own ray hits its
// box, so each ray tests the triangles it would alone, maybe in another order;
// the closest hit is the smallest (t, leaf index) either way (leaf_intersect.h
// breaks ties by leaf index), so a packet answers exactly as its rays traced
// one by one. In the wide layouts a node that at most kHybridSwitch lanes
// enter is handed to those lanes' rays one by one (traverse_wide_from, with
// the lane's tfar and closest hit so far), which changes nothing in the answers.
//
// Built only where AVX-512F is available (HPRT_HAS_PACKETS); the backend
// traces rays one by one elsewhere.
#pragma once

#if defined(__AVX512F__)
#define HPRT_HAS_PACKETS 1

#include <immintrin.h>

#include <cstddef>
#include <cstdint>
#include <limits>

#include "bvh/intersect/leaf_intersect.h"
#include "bvh/traverse/packet_nodes.h"
#include "bvh/traverse/ray_packet.h"
#include "bvh/traverse/simd16.h"
#include "core/force_inline.h"
#include "core/hit.h"
#include "core/ray.h"

namespace hprt {

// Hybrid traversal (Benthin, Wald, Woop, Ernst & Mark, "Combining Single and
// Packet-Ray Tracing for Arbitrary Ray Distributions on the Intel MIC
// Architecture", TVCG 2012; Embree's BVHNIntersectorKHybrid): at a node that
// only this many lanes still enter, each of them goes on alone
// (traverse_wide_from), testing one ray against all children at once instead
// of 16 lanes child by child. Two, as Embree's switch for coherent packets.
inline constexpr int kHybridSwitch = 2;
#if defined(HPRT_HAS_LEAF_LANES)
inline constexpr bool kLeafLanes = true;
#else
inline constexpr bool kLeafLanes = false;
#endif

namespace detail {

struct alignas(64) PacketStackEntry {
  __m512 entry;
  uint64_t ref;
  __mmask16 lanes;  // the lanes that hit the node
};

}  // namespace detail

// Traces rays[0..16), all valid (ray_is_valid). Closest hit: hits[l] is set for
// every lane (a miss is Hit{}), or with `columns` (rays 0..16 of it) the
// lane's answer there instead. Any hit: occluded[l] is 1 or 0. `hits` and
// `columns` are used only without kAnyHit, `occluded` only with it.
template <typename Test, bool kAnyHit, typename Bvh>
void traverse_packet(const Bvh& bvh, const Ray* rays, Hit* hits, uint8_t* occluded,
                     const HitColumnWriter* columns = nullptr) {
  using Nodes = detail::PacketNodes<Bvh>;
  constexpr int N = Nodes::kMaxChildren;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  ClosestHit closest[kPacketSize];
  if (bvh.empty()) {
    for (int l = 0; l < kPacketSize; ++l) {
      if constexpr (kAnyHit) {
        occluded[l] = 0;
      } else if (columns) {
        columns->out.write_miss(size_t(l));
      } else {
        hits[l] = Hit{};
      }
    }
    return;
  }
  const Nodes layout{bvh};
  const LeafTriangles& tris = bvh.triangles;
  detail::RayPacket<Test> packet(rays, layout.bounds());
  float* const tfar_lane = packet.tfar_lane;
  __m512 tfar = _mm512_load_ps(tfar_lane);
  float tfar_max = detail::reduce_max16(tfar);  // over every lane: bounds the active ones
  __mmask16 done = 0;                           // any hit: lanes already occluded

  detail::PacketStackEntry stack[Nodes::kStackSize];
  int sp = 0;
  __mmask16 active = 0;
  NodeRef cur = layout.root(packet, tfar, active);
  if (!active) cur = NodeRef{};
  for (;;) {
    while (cur.is_inner()) {
      if constexpr (Nodes::kHandsOver) {
        if (__builtin_popcount(active) <= kHybridSwitch) {
          packet.prepare(active);
          for (unsigned m = active; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            if (layout.template trace_lane<Test, kAnyHit>(
                    cur, rays[l], packet.prep[l], packet.tnear_lane[l], tfar_lane[l], closest[l])) {
              tfar_lane[l] = -kInf;  // occluded: this lane is done
              done |= __mmask16(1u << l);
            }
          }
          tfar = _mm512_load_ps(tfar_lane);
          tfar_max = detail::reduce_max16(tfar);
          cur = NodeRef{};
          break;
        }
      }
      __m512 entry[N];
      float key[N];
      __mmask16 hit[N];
      NodeRef child[N];
      int order[N];
      int count = 0;
      const unsigned slots = layout.frustum_slots(cur, packet, tfar_max);
      layout.for_each_child(cur, slots, [&](const auto& box, NodeRef c, int i) {
        child[i] = c;
        hit[i] = detail::slab_packet(packet, box, tfar, active, entry[i]);
        if (hit[i]) {
          if (c.is_leaf())
            Test::prefetch(tris, c.leaf_range());
          else
            layout.prefetch_inner(c);
          order[count++] = i;
        }
      });
      if (count == 0) {
        cur = NodeRef{};
        break;
      }
      if (!kAnyHit && count > 1) {
        // Nearest first: insertion sort of at most N keys.
        for (int k = 0; k < count; ++k)
          key[order[k]] = detail::masked_min16(hit[order[k]], entry[order[k]]);
        for (int a = 1; a < count; ++a) {
          const int o = order[a];
          int b = a;
          for (; b > 0 && key[order[b - 1]] > key[o]; --b) order[b] = order[b - 1];
          order[b] = o;
        }
      }
      for (int k = count - 1; k > 0; --k) {
        const int i = order[k];
        stack[sp].entry = entry[i];
        stack[sp].ref = child[i].bits;
        stack[sp].lanes = hit[i];
        ++sp;
      }
      cur = child[order[0]];
      active = hit[order[0]];
    }
    if (cur.is_leaf()) {
      packet.prepare(active);
      const LeafRange leaf = cur.leaf_range();
      const uint32_t end = leaf.first + leaf.count;
      bool all_lanes = false;
      if constexpr (detail::RayPacket<Test>::kLaneTest) {
        // One triangle on the lanes of the rays, or each ray on the lanes
        // of the triangles (leaf_intersect.h), whichever is fewer tests.
        const int halves = ((active & 0xFF) != 0) + ((active >> 8) != 0);
        all_lanes = packet.lanes.usable() &&
                    (!kLeafLanes || __builtin_popcount(active) >= int(leaf.count) * halves);
        alignas(64) float t[kPacketSize], u[kPacketSize], v[kPacketSize];
        for (uint32_t i = leaf.first; i < end && active && all_lanes; ++i) {
          const __mmask16 h = packet.lanes.intersect(tris, leaf, i, tfar_lane, active, t, u, v);
          for (unsigned m = h; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            if (!kAnyHit && closest[l].loses_tie(i, t[l])) continue;
            closest[l].keep(i, leaf, TriangleHit{t[l], u[l], v[l]});
            tfar_lane[l] = kAnyHit ? -kInf : t[l];
            if constexpr (kAnyHit) {
              done |= __mmask16(1u << l);
              active &= __mmask16(~(1u << l));
            }
          }
        }
      }
      // Lanes whose rays differ in axes: each lane's own leaf test.
      for (unsigned m = all_lanes ? 0u : unsigned(active); m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (intersect_leaf<Test, kAnyHit, false>(packet.prep[l], tris, leaf, packet.tnear_lane[l],
                                                 tfar_lane[l], closest[l], nullptr)) {
          tfar_lane[l] = -kInf;  // occluded: this lane is done
          done |= __mmask16(1u << l);
          active &= __mmask16(~(1u << l));
        }
      }
      if constexpr (kAnyHit)
        if (done == 0xFFFF) break;
      tfar = _mm512_load_ps(tfar_lane);
      tfar_max = detail::reduce_max16(tfar);
    }
    // Pop the next entry that may still hold a closer hit for some lane.
    active = 0;
    while (sp > 0 && !active) {
      --sp;
      active = _mm512_mask_cmp_ps_mask(stack[sp].lanes, stack[sp].entry, tfar, _CMP_LE_OQ);
    }
    if (!active) break;
    cur = NodeRef{stack[sp].ref};
  }
  if constexpr (!kAnyHit)
    if (columns) {
      columns->write_packet(closest);
      return;
    }
  for (int l = 0; l < kPacketSize; ++l) {
    if constexpr (kAnyHit) {
      occluded[l] = (done >> l) & 1;
    } else {
      hits[l] = Hit{};
      if (closest[l].found) closest[l].store(tris, hits[l]);
    }
  }
}

}  // namespace hprt

#endif  // __AVX512F__
