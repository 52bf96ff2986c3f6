// compute_tree_stats: counts, depth (root = 1), leaf sizes, the normalised SAH
// cost of docs/ARCHITECTURE.md (inner 1, leaf = its triangle count, each times
// SA(node)/SA(root), summed in double; build_tree_sah_cost alone) and the
// 64-bit tree hash.
//
// tree_hash: every node and every prim_order entry hashed on its own, with
// its index, and the hashes summed (mod 2^64), so it runs in parallel and
// does not depend on the order of the sum. Node i: h = splitmix64_mix(h ^ w) from
// h = splitmix64_mix(seed ^ i) over the words: the six bound floats' bits (three
// words), (right, first), count. prim_order entry k: the same over its
// (geomID, primID). The splitmix64 finaliser is a bijection, so a
// change of any one word changes that element's hash, and the sum. The node
// count, prim count and both sums are chained into the result.
//
// Work is split into fixed chunks whose partial results are combined in
// chunk order: the SAH sum (double) is the same for any thread count.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <vector>

#include "bvh/builders/builders.h"
#include "core/splitmix64.h"

namespace hprt {

namespace {

constexpr size_t kChunk = 16384;
constexpr uint64_t kSeed = kSplitMixGamma;
constexpr uint64_t kNodeSeed = 0x6a09e667f3bcc909ull;
constexpr uint64_t kPrimSeed = 0xbb67ae8584caa73bull;

uint64_t pack(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }
uint64_t pack(float a, float b) {
  return pack(std::bit_cast<uint32_t>(a), std::bit_cast<uint32_t>(b));
}

uint64_t node_hash(const BuildNode& n, size_t i) {
  uint64_t h = splitmix64_mix(kNodeSeed ^ i);
  h = splitmix64_mix(h ^ pack(n.bounds.min.x, n.bounds.min.y));
  h = splitmix64_mix(h ^ pack(n.bounds.min.z, n.bounds.max.x));
  h = splitmix64_mix(h ^ pack(n.bounds.max.y, n.bounds.max.z));
  h = splitmix64_mix(h ^ pack(n.right, n.first));
  return splitmix64_mix(h ^ n.count);
}

// A root of zero area (cannot happen with valid triangles unless it
// underflows) weighs every node 1.
double root_area_of(const BuildTree& tree) {
  return tree.nodes.empty() ? 0.0 : tree.nodes[0].bounds.half_area();
}
double sah_term(const BuildNode& nd, double root_area) {
  const double w = root_area > 0.0 ? nd.bounds.half_area() / root_area : 1.0;
  return nd.is_leaf() ? w * nd.count : w;
}
size_t chunks_of(size_t n) { return (n + kChunk - 1) / kChunk; }

struct ChunkStats {
  size_t leaves = 0, leaf_prims = 0;
  uint32_t max_leaf = 0;
  double cost = 0.0;
  uint64_t node_sum = 0, prim_sum = 0;
};

}  // namespace

TreeStats compute_tree_stats(const BuildTree& tree, const PrimInfo& prims) {
  TreeStats s;
  s.triangles = prims.size();
  s.invalid_triangles = prims.invalid;
  const size_t n = tree.nodes.size(), m = tree.prim_order.size();
  s.nodes = n;
  const size_t chunks = chunks_of(std::max(n, m));
  std::vector<ChunkStats> part(chunks);
  const double root_area = root_area_of(tree);
  tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
    ChunkStats& p = part[c];
    for (size_t i = c * kChunk, e = std::min(n, i + kChunk); i < e; ++i) {
      const BuildNode& nd = tree.nodes[i];
      if (nd.is_leaf()) {
        ++p.leaves;
        p.leaf_prims += nd.count;
        p.max_leaf = std::max(p.max_leaf, nd.count);
      }
      p.cost += sah_term(nd, root_area);
      p.node_sum += node_hash(nd, i);
    }
    for (size_t k = c * kChunk, e = std::min(m, k + kChunk); k < e; ++k) {
      const uint32_t q = tree.prim_order[k];
      const PrimRef r = q < prims.refs.size() ? prims.refs[q] : PrimRef{~0u, q};
      p.prim_sum += splitmix64_mix(splitmix64_mix(kPrimSeed ^ k) ^ pack(r.geom_id, r.prim_id));
    }
  });
  ChunkStats all;
  for (const ChunkStats& p : part) {
    all.leaves += p.leaves;
    all.leaf_prims += p.leaf_prims;
    all.max_leaf = std::max(all.max_leaf, p.max_leaf);
    all.cost += p.cost;
    all.node_sum += p.node_sum;
    all.prim_sum += p.prim_sum;
  }
  s.leaves = all.leaves;
  s.max_leaf_size = static_cast<int>(all.max_leaf);
  s.avg_leaf_size = s.leaves ? double(all.leaf_prims) / double(s.leaves) : 0.0;
  s.sah_cost = n ? all.cost : 0.0;
  // Depth in one pass in index order: children follow their parent in the
  // canonical layout; a link that does not (malformed tree) is not followed.
  if (n) {
    std::vector<uint32_t> depth(n, 0);
    depth[0] = 1;
    uint32_t deepest = 1;
    for (size_t i = 0; i < n; ++i) {
      const BuildNode& nd = tree.nodes[i];
      if (nd.is_leaf() || depth[i] == 0) continue;
      const uint32_t d = depth[i] + 1;
      if (i + 1 < n) depth[i + 1] = d;
      if (nd.right > i && nd.right < n) depth[nd.right] = d;
      deepest = std::max(deepest, d);
    }
    s.depth = static_cast<int>(deepest);
  }
  uint64_t h = splitmix64_mix(kSeed ^ n);
  h = splitmix64_mix(h ^ all.node_sum);
  h = splitmix64_mix(h ^ m);
  s.tree_hash = splitmix64_mix(h ^ all.prim_sum);
  return s;
}

// The same chunks and order of summation as compute_tree_stats (chunks past
// the nodes add 0), so both give the same bits.
double build_tree_sah_cost(const BuildTree& tree) {
  const size_t n = tree.nodes.size();
  const double root_area = root_area_of(tree);
  std::vector<double> part(chunks_of(n), 0.0);
  tbb::parallel_for(size_t{0}, part.size(), [&](size_t c) {
    double cost = 0.0;
    for (size_t i = c * kChunk, e = std::min(n, i + kChunk); i < e; ++i)
      cost += sah_term(tree.nodes[i], root_area);
    part[c] = cost;
  });
  double all = 0.0;
  for (const double p : part) all += p;
  return all;
}

}  // namespace hprt
