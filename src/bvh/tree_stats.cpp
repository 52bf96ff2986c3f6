// compute_tree_stats: counts, depth (root = 1), leaf sizes, the normalised SAH
// cost of DESIGN.md (inner 1, leaf = its triangle count, each times
// SA(node)/SA(root), summed in double) and the 64-bit tree hash.
//
// tree_hash: h = mix64(h ^ w) over 64-bit words w (mix64 = the splitmix64
// finaliser, a bijection, so changing any one word changes the hash): node
// count, then per node the six bound floats' bits, right, first, count; then
// prim_order as (geomID, primID) pairs.
#include <algorithm>
#include <bit>
#include <cstring>
#include <vector>

#include "bvh/builders.h"

namespace hprt {

namespace {

uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

struct Hasher {
  uint64_t h = 0x9e3779b97f4a7c15ull;
  void add(uint64_t w) { h = mix64(h ^ w); }
  void add2(uint32_t a, uint32_t b) { add((uint64_t(a) << 32) | b); }
};

}  // namespace

TreeStats compute_tree_stats(const BuildTree& tree, const PrimInfo& prims) {
  TreeStats s;
  s.triangles = prims.size();
  s.invalid_triangles = prims.invalid;
  s.nodes = tree.nodes.size();
  Hasher hash;
  hash.add(tree.nodes.size());
  if (!tree.nodes.empty()) {
    const double root_area = tree.nodes[0].bounds.half_area();
    size_t leaf_prims = 0;
    double cost = 0.0;
    for (const BuildNode& n : tree.nodes) {
      // A root of zero area (cannot happen with valid triangles unless it
      // underflows) weighs every node 1.
      const double w = root_area > 0.0 ? n.bounds.half_area() / root_area : 1.0;
      if (n.is_leaf()) {
        ++s.leaves;
        leaf_prims += n.count;
        s.max_leaf_size = std::max<int>(s.max_leaf_size, static_cast<int>(n.count));
        cost += w * n.count;
      } else {
        cost += w;
      }
    }
    s.sah_cost = cost;
    s.avg_leaf_size = s.leaves ? double(leaf_prims) / double(s.leaves) : 0.0;
    // Depth: explicit stack of (node, depth); the tree is at most kMaxBuildDepth deep
    // for our builders but this copes with any valid tree.
    std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
    while (!stack.empty()) {
      auto [i, d] = stack.back();
      stack.pop_back();
      s.depth = std::max(s.depth, d);
      const BuildNode& n = tree.nodes[i];
      if (!n.is_leaf()) {
        stack.push_back({n.right, d + 1});
        stack.push_back({i + 1, d + 1});
      }
    }
  }
  for (const BuildNode& n : tree.nodes) {
    hash.add2(std::bit_cast<uint32_t>(n.bounds.min.x), std::bit_cast<uint32_t>(n.bounds.min.y));
    hash.add2(std::bit_cast<uint32_t>(n.bounds.min.z), std::bit_cast<uint32_t>(n.bounds.max.x));
    hash.add2(std::bit_cast<uint32_t>(n.bounds.max.y), std::bit_cast<uint32_t>(n.bounds.max.z));
    hash.add2(n.right, n.first);
    hash.add(n.count);
  }
  hash.add(tree.prim_order.size());
  for (uint32_t p : tree.prim_order) {
    const PrimRef r = p < prims.refs.size() ? prims.refs[p] : PrimRef{~0u, p};
    hash.add2(r.geom_id, r.prim_id);
  }
  s.tree_hash = hash.h;
  return s;
}

}  // namespace hprt
