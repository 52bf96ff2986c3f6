// The text `hprt validate rays` prints for a ray diff (the public API returns
// the same text): counts per verdict, t errors, malformed answers and the
// pass/fail line for the backend under test.
#pragma once

#include <string>

#include "validators/ray_diff.h"

namespace hprt {

struct RayDiffLabels {
  std::string backend;    // the backend under test's configuration, e.g. "bvh/parallel/watertight"
  std::string reference;  // e.g. "embree/medium"
  bool occluded = false;
  std::string source;      // where the rays came from: "random, seed 1" or a .rays path
  std::string mismatches;  // where the mismatching rays were written, "" when nowhere
};

// Several lines, each ending in '\n'.
std::string ray_diff_summary(const RayDiffResult& r, const RayDiffLabels& labels);

}  // namespace hprt
