// When the bvh backend's update() rebuilds instead of refitting
// (BackendOptions::update): `rebuild` always; `refit` only when the refit
// cannot stand (the mesh layout changed, a triangle left out at the last
// build became valid, or the refit found a triangle that became invalid);
// `adaptive` also when the refitted tree's SAH cost has grown past
// adaptive_factor times its cost right after the last rebuild. `auto` is
// `refit` here; after the refit, auto_update_policy.h decides.
#pragma once

#include "backends/intersector.h"

namespace hprt {

// Before refitting: whether the tree cannot be refitted at all. tree_fits:
// the tree was built over the same meshes and triangle set (mesh_record.h).
inline bool must_rebuild(UpdateStrategy strategy, bool tree_fits) {
  return strategy == UpdateStrategy::kRebuild || !tree_fits;
}

// After refitting: whether to rebuild all the same. refit_valid: the refit
// kept every triangle valid; sah_cost: the refitted tree's; rebuild_sah_cost:
// the tree's right after the last rebuild.
inline bool rebuild_after_refit(const BackendOptions& options, bool refit_valid, double sah_cost,
                                double rebuild_sah_cost) {
  if (!refit_valid) return true;
  return options.update == UpdateStrategy::kAdaptive &&
         sah_cost > double(options.adaptive_factor) * rebuild_sah_cost;
}

}  // namespace hprt
