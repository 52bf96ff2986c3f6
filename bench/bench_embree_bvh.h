// Embree's generic binned-SAH builder (rtcBuildBVH) building a binary tree
// with leaves of 1..max_leaf_size primitives and our SAH constants, and the
// normalised SAH cost of that tree computed exactly as tree_stats.cpp does for
// ours (inner nodes 1, leaves their primitive count, weighted by SA/SA(root)),
// so tree quality is compared node for node.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "bvh/input/build_options.h"
#include "bvh/input/prim_info.h"

namespace hprt::bench {

struct EmbreeBvhResult {
  double build_ms = 0.0;  // rtcBuildBVH only (primitive array copy excluded)
  double sah_cost = 0.0;
  size_t nodes = 0;  // inner + leaves
  size_t leaves = 0;
  int depth = 0;
};

// Owns an Embree device (`threads` threads, 0 = all) and its BVH object; the
// primitive array is prepared once from `prims` and copied before each build
// (rtcBuildBVH reorders it). Call build() from inside run_with_threads().
class EmbreeBvhBuilder {
 public:
  EmbreeBvhBuilder(const PrimInfo& prims, int threads);
  ~EmbreeBvhBuilder();
  EmbreeBvhBuilder(const EmbreeBvhBuilder&) = delete;
  EmbreeBvhBuilder& operator=(const EmbreeBvhBuilder&) = delete;

  // One build at RTC_BUILD_QUALITY_MEDIUM with options.max_leaf_size and
  // options.sah; throws std::runtime_error when Embree fails.
  EmbreeBvhResult build(const BuildOptions& options);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hprt::bench
