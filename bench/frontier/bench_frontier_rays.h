// The rays of `hprt bench frontier`: hard-case sets with their exact answers
// (the arbiter over every triangle, brute force) and the trace rays timed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "backends/intersector.h"
#include "core/ray.h"
#include "core/scene.h"
#include "validators/arbiter.h"

namespace hprt::bench {

// One hard-case ray set with its exact answers.
struct HardSet {
  std::string label;  // "vertex-probe", "grazing@1e6", ...
  std::string group;  // column it counts in: probe, grazing, axis, offset
  const Scene* scene = nullptr;
  std::vector<Ray> rays;
  std::vector<ArbiterAnswer> answers;
};

// Every configuration's rays, made once.
struct FrontierRays {
  std::vector<HardSet> hard;
  size_t hard_total = 0;             // rays over all hard-case sets
  std::vector<Ray> trace;            // primary + random, timed
  std::vector<std::string> skipped;  // hard-case sets the mesh does not allow, with why
};

// `base` scaled to radius 10 and moved to (1e6, -1e6, 1e6) (float spacing 1/16).
Scene offset_scene(const Scene& base);

// Trace rays (`trace_rays` primary + as many random, generated through the
// embree backend) and vertex/edge probes, grazing and axis rays
// (`hard_rays` per set) on `scene` and on `far`, with their exact answers;
// all at `threads` threads. The sets keep pointers to `scene` and `far`.
FrontierRays make_frontier_rays(const Scene& scene, const Scene& far, int threads, size_t hard_rays,
                                size_t trace_rays);

// Rays of `set` whose hit from `b` the exact arbiter rejects, by the rule of
// `hprt validate rays` (closest_hit_right, validators/ray_diff.h).
size_t count_wrong(const HardSet& set, const Intersector& b);

}  // namespace hprt::bench
