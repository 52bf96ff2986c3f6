// Full-sweep SAH builder (Algorithm 1): at every node, sort the node's
// primitives by centroid on each axis, sweep boxes from both ends and price
// every cut; O(n log^2 n). The reference for build_presorted (same tree).
#include <algorithm>
#include <numeric>
#include <utility>

#include "bvh/builders/builder_common.h"
#include "bvh/builders/builders.h"
#include "bvh/split/sweep_split.h"

namespace hprt {

namespace {

class SweepBuilder {
 public:
  SweepBuilder(const PrimInfo& prims, const BuildOptions& o, BuildTree& tree)
      : prims_(prims), o_(o), tree_(tree) {
    const size_t n = prims.size();
    for (auto& k : keys_) k.resize(n);
  }

  void recurse(size_t begin, size_t end, int depth) {
    uint32_t* ids = tree_.prim_order.data() + begin;
    const size_t n = end - begin;
    const auto [bounds, cb] = range_bounds(prims_, ids, n);
    const size_t max_leaf = static_cast<size_t>(o_.max_leaf_size);
    const float area = bounds.half_area();
    SweepSplit best;
    bool leaf;
    if (n <= 1) {
      leaf = true;
    } else if (must_split_median(depth, n, kMaxBuildDepth) || !any_centroid_extent(cb)) {
      leaf = n <= max_leaf;
    } else {
      for (int a = 0; a < 3; ++a) {
        if (!(cb.max[a] > cb.min[a])) continue;
        auto& k = keys_[a];
        for (size_t i = 0; i < n; ++i) k[i] = {prims_.centroids[ids[i]][a], ids[i]};
        std::sort(k.begin(), k.begin() + n);  // (centroid, index): a total order
        for (size_t i = 0; i < n; ++i) sorted_[i] = k[i].second;
        sweep_axis(prims_, o_.sah, a, sorted_.data(), n, area, right_area_, best);
      }
      leaf = sah_make_leaf(o_.sah, o_.max_leaf_size, area, n, best.cost);
    }
    if (leaf) {
      std::sort(ids, ids + n);  // leaves list their primitives by ascending index
      tree_.nodes.push_back(make_leaf(bounds, begin, n));
      return;
    }
    size_t mid;
    if (best.axis >= 0) {
      const auto& k = keys_[best.axis];
      for (size_t i = 0; i < n; ++i) ids[i] = k[i].second;
      mid = begin + best.cut;
    } else {  // fallback: the floor(n/2) smallest indices go left
      std::sort(ids, ids + n);
      mid = begin + n / 2;
    }
    const size_t me = tree_.nodes.size();
    tree_.nodes.push_back(make_inner(bounds));
    recurse(begin, mid, depth + 1);
    tree_.nodes[me].right = static_cast<uint32_t>(tree_.nodes.size());
    recurse(mid, end, depth + 1);
  }

  std::vector<uint32_t> sorted_;

 private:
  const PrimInfo& prims_;
  const BuildOptions& o_;
  BuildTree& tree_;
  std::vector<std::pair<float, uint32_t>> keys_[3];
  std::vector<float> right_area_;
};

}  // namespace

BuildTree build_sweep(const PrimInfo& prims, const BuildOptions& options) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  tree.prim_order.resize(n);
  std::iota(tree.prim_order.begin(), tree.prim_order.end(), 0u);
  tree.nodes.reserve(2 * n - 1);
  SweepBuilder b(prims, options, tree);
  b.sorted_.resize(n);
  b.recurse(0, n, 1);
  return tree;
}

}  // namespace hprt
