// The order in which a wide node's hit children go on the traversal stack
// (bvh/traverse/wide_child_order.h): distances decreasing towards the top,
// equal distances in child order, exactly the hit children, the nearest
// returned; the AVX-512 network writes the same stack as the insertion sort.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "bvh/traverse/wide_child_order.h"
#include "core/splitmix64.h"

namespace hprt {
namespace {

using detail::WideStackEntry;

template <int N>
WideNode<N> node_with_distinct_children(SplitMix64& rng) {
  WideNode<N> node;
  for (int i = 0; i < N; ++i)
    node.child[i] = NodeRef::leaf(uint32_t(rng.below(1u << 20)) * N + uint32_t(i), 1 + i);
  return node;
}

// Distances with many ties, zeros, negatives, infinities and subnormals.
float draw_distance(SplitMix64& rng) {
  static const float kPool[] = {0.0f,  -0.0f, 1.0f,   1.0f,
                                2.5f,  -3.0f, 1e-40f, std::numeric_limits<float>::infinity(),
                                1e30f, 0.5f};
  return rng.coin() ? kPool[rng.below(std::size(kPool))] : 100.0f * rng.uniform() - 10.0f;
}

// What the stack must hold after pushing the hit children of `mask` on top of
// `below` entries, and that the returned ref is the popped nearest.
template <int N>
void expect_ordered(const WideNode<N>& node, const float* dist, unsigned mask,
                    const std::vector<WideStackEntry>& stack, int below, int sp, NodeRef entered) {
  const int hit = __builtin_popcount(mask);
  ASSERT_EQ(sp, below + hit - 1);
  std::vector<WideStackEntry> all(stack.begin() + below, stack.begin() + below + hit - 1);
  all.push_back({entered.bits, 0.0f});
  // Each hit child exactly once, each with its own distance.
  std::vector<int> child_at(static_cast<size_t>(hit), -1);
  for (int k = 0; k < hit; ++k) {
    int found = -1;
    for (int i = 0; i < N; ++i) {
      if (node.child[i].bits == all[size_t(k)].ref) found = i;
    }
    ASSERT_GE(found, 0);
    ASSERT_TRUE(mask >> found & 1u);
    child_at[size_t(k)] = found;
    if (k + 1 < hit) {
      EXPECT_EQ(all[size_t(k)].entry, dist[found]);
    }
  }
  for (int k = 0; k + 1 < hit; ++k) {
    const float a = dist[child_at[size_t(k)]], b = dist[child_at[size_t(k) + 1]];
    EXPECT_TRUE(a > b || (a == b && child_at[size_t(k)] < child_at[size_t(k) + 1]))
        << "position " << k << ": child " << child_at[size_t(k)] << " at " << a << ", then child "
        << child_at[size_t(k) + 1] << " at " << b;
  }
}

template <int N>
void check_random_nodes(uint64_t seed) {
  SplitMix64 rng(seed);
  for (int round = 0; round < 20000; ++round) {
    const WideNode<N> node = node_with_distinct_children<N>(rng);
    alignas(32) float dist[N];
    for (float& d : dist) d = draw_distance(rng);
    unsigned mask = 0;
    while (__builtin_popcount(mask) < 3) mask = unsigned(rng.below(1u << N));
    const int below = int(rng.below(5));
    const WideStackEntry filler{~uint64_t(0), -1.0f};
    std::vector<WideStackEntry> a(size_t(detail::kWideStackSize<N>), filler), b = a;
    int sp_a = below, sp_b = below;
    const NodeRef ea = detail::push_children_sorted<N>(node, dist, mask, a.data(), sp_a);
    const NodeRef eb = detail::push_children_sorted_insertion<N>(node, dist, mask, b.data(), sp_b);
    SCOPED_TRACE(round);
    expect_ordered<N>(node, dist, mask, a, below, sp_a, ea);
    expect_ordered<N>(node, dist, mask, b, below, sp_b, eb);
    // The entries below the pushed run are untouched.
    for (int k = 0; k < below; ++k) EXPECT_EQ(a[size_t(k)].ref, filler.ref);
    ASSERT_EQ(ea, eb);
    ASSERT_EQ(sp_a, sp_b);
    for (int k = 0; k < sp_a; ++k) {
      ASSERT_EQ(a[size_t(k)].ref, b[size_t(k)].ref) << k;
      ASSERT_EQ(a[size_t(k)].entry, b[size_t(k)].entry) << k;
    }
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(WideChildOrder, EightWideNodesStackedFarthestFirstAsTheInsertionSort) {
  check_random_nodes<8>(11);
}

TEST(WideChildOrder, FourWideNodesStackedFarthestFirst) { check_random_nodes<4>(12); }

TEST(WideChildOrder, AllEightChildrenAtOneDistanceKeepChildOrder) {
  SplitMix64 rng(3);
  const WideNode<8> node = node_with_distinct_children<8>(rng);
  alignas(32) const float dist[8] = {2, 2, 2, 2, 2, 2, 2, 2};
  std::vector<WideStackEntry> stack(size_t(detail::kWideStackSize<8>));
  int sp = 0;
  const NodeRef entered = detail::push_children_sorted<8>(node, dist, 0xFF, stack.data(), sp);
  ASSERT_EQ(sp, 7);
  EXPECT_EQ(entered, node.child[7]);  // the top: the last child
  for (int k = 0; k < 7; ++k) EXPECT_EQ(stack[size_t(k)].ref, node.child[k].bits);
}

}  // namespace
}  // namespace hprt
