// Full-sweep SAH evaluation over one axis' sorted primitive order, shared by
// the sweep (Algorithm 1) and presorted (Algorithm 2) builders so both price
// every cut with the same operations and pick bit-identical splits. Order on
// an axis: centroid, then primitive index (a total order).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvh/input/prim_info.h"
#include "bvh/split/sah.h"

namespace hprt {

struct SweepSplit {
  int axis = -1;
  size_t cut = 0;  // left = the first `cut` primitives of the axis order
  float cost = kNoSplit;
};

// Evaluates the n-1 cuts of ids[0, n) (sorted on `axis`); updates `best` when a
// cut is strictly cheaper, so ties keep the lowest axis, then the lowest cut.
inline void sweep_axis(const PrimInfo& prims, const SahParams& sah, int axis, const uint32_t* ids,
                       size_t n, float parent_area, std::vector<float>& right_area,
                       SweepSplit& best) {
  right_area.resize(n);
  const AABB* bx = prims.bounds.data();
  AABB acc;
  for (size_t i = n - 1; i > 0; --i) {
    acc.extend(bx[ids[i]]);
    right_area[i] = acc.half_area();
  }
  AABB left;
  for (size_t i = 0; i + 1 < n; ++i) {
    left.extend(bx[ids[i]]);
    const float cost =
        sah_split_cost(sah, parent_area, left.half_area(), i + 1, right_area[i + 1], n - i - 1);
    if (cost < best.cost) {
      best.axis = axis;
      best.cut = i + 1;
      best.cost = cost;
    }
  }
}

}  // namespace hprt
