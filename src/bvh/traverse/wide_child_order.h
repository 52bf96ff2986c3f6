// The wide traversal's stack and the order in which a node's hit children go
// on it: when three or more are hit, all are pushed so that entry distances
// decrease towards the top (the nearest is entered first), equal distances in
// child order (the lower child lower on the stack). Portable code sorts the
// pushed run by insertion; with AVX-512 an 8-wide node's children are ordered
// by a bitonic network in one register instead: on meshes whose boxes
// overlap, where most nodes have several hit children, the insertion sort's
// mispredicted branches were a tenth of the traversal's time. Both give the
// same stack, entry for entry.
#pragma once

#include <cstdint>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "bvh/builders/build_tree.h"
#include "bvh/layout/node_wide.h"
#include "core/force_inline.h"

namespace hprt {
namespace detail {

// Plain data (no NodeRef default member), so the stack array is left
// uninitialised: it is large (N = 8: 457 entries) and set per ray.
struct WideStackEntry {
  uint64_t ref;
  float entry;
};
static_assert(sizeof(WideStackEntry) == 16);

// Each wide level pushes at most N - 1 entries and the tree is no deeper
// than the binary tree it was collapsed from; the network writes all N
// entries of a node before keeping the hit ones, hence N more.
template <int N>
inline constexpr int kWideStackSize = 1 + (N - 1) * kMaxBuildDepth + N;

// Pushes the children of `mask` (three or more) with their entry distances
// `dist`, ordered as the file's comment says, then pops and returns the
// nearest.
template <int N>
HPRT_FORCE_INLINE NodeRef push_children_sorted_insertion(const WideNode<N>& node, const float* dist,
                                                         unsigned mask, WideStackEntry* stack,
                                                         int& sp) {
  const int base = sp;
  for (; mask; mask &= mask - 1) {
    const int i = __builtin_ctz(mask);
    stack[sp++] = {node.child[i].bits, dist[i]};
  }
  for (int a = base + 1; a < sp; ++a) {
    const WideStackEntry e = stack[a];
    int b = a;
    for (; b > base && stack[b - 1].entry < e.entry; --b) stack[b] = stack[b - 1];
    stack[b] = e;
  }
  return NodeRef{stack[--sp].ref};
}

#if defined(__AVX512F__)
// The same for an 8-wide node: one 64-bit key per child, its distance's bits
// made order-preserving as an unsigned integer in the upper half and 7 - child
// in the lower, children not hit 0 (below every hit child's key); a
// descending bitonic sort of the eight keys puts the hit children first,
// farthest first, and the keys' lower bits give the order of their refs and
// distances, written as eight stack entries of which the hit ones are kept.
HPRT_FORCE_INLINE NodeRef push_children_sorted_network(const WideNode<8>& node, const float* dist,
                                                       unsigned mask, WideStackEntry* stack,
                                                       int& sp) {
  // Mask forms with every lane on: g++ 12 reports the plain 512-bit forms'
  // undefined pass-through operand as maybe-uninitialized.
  constexpr __mmask8 kAll = 0xFF;
  const __m256 d = _mm256_loadu_ps(dist);
  // + 0 turns -0 into +0, which the insertion sort's < takes as equal.
  const __m256i bits = _mm256_castps_si256(_mm256_add_ps(d, _mm256_setzero_ps()));
  // Negative floats: flip every bit; others: flip the sign bit.
  const __m256i ordered = _mm256_xor_si256(
      bits, _mm256_or_si256(_mm256_srai_epi32(bits, 31), _mm256_set1_epi32(INT32_MIN)));
  const __m512i reverse_child = _mm512_set_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  __m512i key = _mm512_or_si512(
      _mm512_maskz_slli_epi64(kAll, _mm512_maskz_cvtepu32_epi64(kAll, ordered), 32), reverse_child);
  key = _mm512_maskz_mov_epi64(__mmask8(mask), key);
  // One compare-exchange layer: each lane meets lane i ^ j and keeps the
  // larger key where `keep_max` has its bit, the smaller elsewhere.
  const auto layer = [&](__m512i partner, __mmask8 keep_max) {
    const __m512i other = _mm512_maskz_permutexvar_epi64(kAll, partner, key);
    key = _mm512_mask_blend_epi64(keep_max, _mm512_maskz_min_epu64(kAll, key, other),
                                  _mm512_maskz_max_epu64(kAll, key, other));
  };
  const __m512i xor1 = _mm512_set_epi64(6, 7, 4, 5, 2, 3, 0, 1);
  const __m512i xor2 = _mm512_set_epi64(5, 4, 7, 6, 1, 0, 3, 2);
  const __m512i xor4 = _mm512_set_epi64(3, 2, 1, 0, 7, 6, 5, 4);
  // Merge sizes 2, 4, 8; lane i keeps the maximum when (i < partner) equals
  // "i's block of the merge size ascends" ((i & size) == 0), which sorts the
  // whole register in descending order.
  layer(xor1, 0x99);
  layer(xor2, 0xC3);
  layer(xor1, 0xA5);
  layer(xor4, 0x0F);
  layer(xor2, 0x33);
  layer(xor1, 0x55);
  const __m512i child =
      _mm512_sub_epi64(_mm512_set1_epi64(7), _mm512_and_si512(key, _mm512_set1_epi64(7)));
  const __m512i refs = _mm512_maskz_permutexvar_epi64(kAll, child, _mm512_loadu_si512(node.child));
  const __m256 sorted_dist = _mm256_permutexvar_ps(_mm512_maskz_cvtepi64_epi32(kAll, child), d);
  const __m512i dist64 = _mm512_maskz_cvtepu32_epi64(kAll, _mm256_castps_si256(sorted_dist));
  WideStackEntry* out = stack + sp;
  _mm512_storeu_si512(
      out, _mm512_permutex2var_epi64(refs, _mm512_set_epi64(11, 3, 10, 2, 9, 1, 8, 0), dist64));
  _mm512_storeu_si512(out + 4, _mm512_permutex2var_epi64(
                                   refs, _mm512_set_epi64(15, 7, 14, 6, 13, 5, 12, 4), dist64));
  sp += __builtin_popcount(mask) - 1;
  return NodeRef{stack[sp].ref};
}
#endif

template <int N>
HPRT_FORCE_INLINE NodeRef push_children_sorted(const WideNode<N>& node, const float* dist,
                                               unsigned mask, WideStackEntry* stack, int& sp) {
#if defined(__AVX512F__)
  if constexpr (N == 8) return push_children_sorted_network(node, dist, mask, stack, sp);
#endif
  return push_children_sorted_insertion(node, dist, mask, stack, sp);
}

}  // namespace detail
}  // namespace hprt
