// Refit of the wide traversal layout (refit_bvh2.h's contract for WideBvh<N>): the
// topology of the last build is kept, leaf triangles are re-gathered and every
// child box recomputed bottom-up. The SAH cost reported is the binary one of
// docs/ARCHITECTURE.md, as bvh2_sah_cost() gives for the binary layout of the same build:
// each wide node also stands for the binary inner nodes collapsed into it
// (WideBvh::collapsed), whose boxes are unions of its slots.
#pragma once

#include "bvh/layout/wide_bvh.h"
#include "bvh/refit/refit_bvh2.h"
#include "core/scene.h"

namespace hprt {

template <int N>
RefitResult refit(WideBvh<N>& bvh, const Scene& scene,
                  RefitTriangles triangles = RefitTriangles::kBoth,
                  const RefitIndex* index = nullptr);

// The binary SAH cost of the build tree `bvh` was collapsed from, from the
// wide layout's boxes (equal to bvh2_sah_cost of its binary layout up to
// summation order). 0 for an empty bvh.
template <int N>
double wide_sah_cost(const WideBvh<N>& bvh);

}  // namespace hprt
