// The surface area heuristic of the report's equation (1), as used by every
// builder: split = C_trav + C_isect * sum_child SA(child)/SA(P) * |child|,
// leaf = C_isect * |P|, where |.| counts triangles, or blocks of
// SahParams::leaf_block triangles. Costs are kept multiplied by SA(P) (half
// areas), which ranks splits the same way and avoids a division per candidate.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "bvh/input/build_options.h"

namespace hprt {

inline constexpr float kNoSplit = std::numeric_limits<float>::infinity();

// |P| in the cost: count primitives, or the blocks of leaf_block they fill.
inline float sah_units(const SahParams& p, size_t count) {
  const size_t b = static_cast<size_t>(p.leaf_block);
  return static_cast<float>(b <= 1 ? count : (count + b - 1) / b);
}

// Leaf cost of |P| primitives in a node of half area `parent_area`, times SA(P).
inline float sah_leaf_cost(const SahParams& p, float parent_area, size_t count) {
  return p.intersection_cost * sah_units(p, count) * parent_area;
}

// a * b + c rounded the same way at every call site. Where the target has
// FMA the compiler may fuse a plain expression differently in each inlined
// copy (-ffp-contract=fast), and the builders' small-node shortcut must price
// a split bit for bit as the bins do; without FMA nothing is fused.
inline float sah_mul_add(float a, float b, float c) {
#ifdef __FMA__
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

// Split cost times SA(P): C_trav * SA(P) + C_isect * (SA(L)*|L| + SA(R)*|R|).
inline float sah_split_cost(const SahParams& p, float parent_area, float left_area,
                            size_t left_count, float right_area, size_t right_count) {
  const float children =
      sah_mul_add(left_area, sah_units(p, left_count), right_area * sah_units(p, right_count));
  return sah_mul_add(p.traversal_cost, parent_area, p.intersection_cost * children);
}

// The leaf rule shared by all builders: never more than max_leaf_size
// primitives, and a leaf whenever it is no dearer than the best split.
inline bool sah_make_leaf(const SahParams& p, int max_leaf_size, float parent_area, size_t count,
                          float best_split_cost) {
  if (count <= 1) return true;
  if (count > static_cast<size_t>(max_leaf_size)) return false;
  return sah_leaf_cost(p, parent_area, count) <= best_split_cost;
}

// Depth guard (see kMaxBuildDepth): a node at `depth` (root 1) holding `count`
// primitives must take an object-median split when depth + ceil(log2(count))
// reaches the limit; median splits then keep every leaf within it.
inline int ceil_log2(size_t n) {
  int r = 0;
  while ((size_t{1} << r) < n) ++r;
  return r;
}
inline bool must_split_median(int depth, size_t count, int max_depth) {
  return depth + ceil_log2(count) >= max_depth;
}

}  // namespace hprt
