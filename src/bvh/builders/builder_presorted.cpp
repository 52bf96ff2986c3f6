// Presorted full-sweep SAH builder (Algorithm 2): sort the primitives once per
// axis at the root (centroid, then index), sweep the three orders at every
// node, and carry them down with a stable partition driven by per-primitive
// left/right flags. Gives exactly build_sweep's tree in O(n log n) per level.
#include <algorithm>
#include <numeric>
#include <utility>

#include "bvh/builders/builder_common.h"
#include "bvh/builders/builders.h"
#include "bvh/split/sweep_split.h"

namespace hprt {

namespace {

class PresortedBuilder {
 public:
  PresortedBuilder(const PrimInfo& prims, const BuildOptions& o, BuildTree& tree)
      : prims_(prims), o_(o), tree_(tree) {
    const size_t n = prims.size();
    std::vector<std::pair<float, uint32_t>> keys(n);
    for (int a = 0; a < 3; ++a) {
      for (uint32_t i = 0; i < n; ++i) keys[i] = {prims.centroids[i][a], i};
      std::sort(keys.begin(), keys.end());  // (centroid, index): the order build_sweep uses
      ord_[a].resize(n);
      for (size_t i = 0; i < n; ++i) ord_[a][i] = keys[i].second;
    }
    left_.assign(n, 0);
    temp_.resize(n);
  }

  void recurse(size_t begin, size_t end, int depth) {
    const size_t n = end - begin;
    const auto [bounds, cb] = range_bounds(prims_, ord_[0].data() + begin, n);
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
        sweep_axis(prims_, o_.sah, a, ord_[a].data() + begin, n, area, right_area_, best);
      }
      leaf = sah_make_leaf(o_.sah, o_.max_leaf_size, area, n, best.cost);
    }
    if (leaf) {
      uint32_t* out = tree_.prim_order.data() + begin;
      std::copy(ord_[0].begin() + begin, ord_[0].begin() + end, out);
      std::sort(out, out + n);  // leaves list their primitives by ascending index
      tree_.nodes.push_back(make_leaf(bounds, begin, n));
      return;
    }
    size_t cut;
    if (best.axis >= 0) {
      cut = best.cut;
      const uint32_t* ids = ord_[best.axis].data() + begin;
      for (size_t i = 0; i < n; ++i) left_[ids[i]] = i < cut ? 1 : 0;
    } else {  // fallback: the floor(n/2) smallest indices go left
      cut = n / 2;
      std::copy(ord_[0].begin() + begin, ord_[0].begin() + end, temp_.begin());
      std::nth_element(temp_.begin(), temp_.begin() + cut, temp_.begin() + n);
      for (size_t i = 0; i < n; ++i) left_[temp_[i]] = i < cut ? 1 : 0;
    }
    for (int a = 0; a < 3; ++a)
      if (a != best.axis) stable_partition(ord_[a].data() + begin, n);
    const size_t me = tree_.nodes.size();
    tree_.nodes.push_back(make_inner(bounds));
    recurse(begin, begin + cut, depth + 1);
    tree_.nodes[me].right = static_cast<uint32_t>(tree_.nodes.size());
    recurse(begin + cut, end, depth + 1);
  }

 private:
  // Order-preserving partition of ids[0, n) by left_ flags.
  void stable_partition(uint32_t* ids, size_t n) {
    size_t w = 0, t = 0;
    for (size_t i = 0; i < n; ++i) {
      if (left_[ids[i]])
        ids[w++] = ids[i];
      else
        temp_[t++] = ids[i];
    }
    std::copy(temp_.begin(), temp_.begin() + t, ids + w);
  }

  const PrimInfo& prims_;
  const BuildOptions& o_;
  BuildTree& tree_;
  std::vector<uint32_t> ord_[3];
  std::vector<uint8_t> left_;
  std::vector<uint32_t> temp_;
  std::vector<float> right_area_;
};

}  // namespace

BuildTree build_presorted(const PrimInfo& prims, const BuildOptions& options) {
  validate_build_options(options);
  BuildTree tree;
  const size_t n = prims.size();
  if (n == 0) return tree;
  tree.prim_order.resize(n);
  tree.nodes.reserve(2 * n - 1);
  PresortedBuilder b(prims, options, tree);
  b.recurse(0, n, 1);
  return tree;
}

}  // namespace hprt
