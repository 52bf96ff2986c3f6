// Tests of build_sweep: canonical layout and invariants, options, fallbacks.
#include <gtest/gtest.h>

#include "tests/support/bvh_builder_checks.h"

namespace hprt::test {
namespace {

TEST(BuilderSweep, InvariantsHoldOnAllMeshes) { check_invariants_on_meshes(build_sweep); }
TEST(BuilderSweep, LeafSizeOptionIsRespected) { check_leaf_sizes(build_sweep); }
TEST(BuilderSweep, InvalidTrianglesAreLeftOutAndCounted) { check_invalid_triangles(build_sweep); }
TEST(BuilderSweep, CoincidentCentroidsFallBackToMedian) { check_coincident_centroids(build_sweep); }
TEST(BuilderSweep, DepthStaysWithinLimit) { check_depth_limit(build_sweep); }
TEST(BuilderSweep, EmptyAndSingleInput) { check_empty_and_single(build_sweep); }
TEST(BuilderSweep, BadOptionsThrow) { check_bad_options(build_sweep); }

}  // namespace
}  // namespace hprt::test
