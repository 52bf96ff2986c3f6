// The auto update policy's choices on fixed figures (auto_update_policy.h):
// before any query time, the adaptive rule with the cheaper build; frames
// without queries -> refit; a tree whose lost query time passes a rebuild's
// cost -> rebuild, with the builder whose best rebuild period is cheaper;
// slow growth -> a rebuild about every sqrt(2 R / (ms_per_cost g)) frames;
// the prediction that lets a rebuild frame skip its refit.
#include <gtest/gtest.h>

#include <cmath>

#include "backends/auto_update_policy.h"

namespace hprt {
namespace {

using Choice = AutoUpdatePolicy::Choice;

TEST(AutoUpdatePolicy, BeforeAnyQueryTimeFollowsTheAdaptiveRule) {
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kSah, 250.0, 100.0);
  EXPECT_EQ(p.after_refit(120.0, {}), Choice::kRefit);
  EXPECT_EQ(p.after_refit(130.0, {}), Choice::kRefit);   // at the factor: keep
  EXPECT_EQ(p.after_refit(131.0, {}), Choice::kMorton);  // the cheaper build
}

TEST(AutoUpdatePolicy, OnceTimedFramesWithoutQueriesOnlyRefit) {
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kSah, 250.0, 100.0);
  EXPECT_EQ(p.after_refit(101.0, {10.0, 100.0}), Choice::kRefit);
  for (int frame = 2; frame < 20; ++frame)
    EXPECT_EQ(p.after_refit(100.0 * frame, {}), Choice::kRefit) << frame;
}

TEST(AutoUpdatePolicy, SlowerQueriesOnAnUnchangedTreeDoNotRebuild) {
  // A gentle wave on a machine that gets busy: the queries take four times
  // as long while the refitted tree's cost barely moves, so the tree is not
  // what got slower.
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kSah, 65.0, 100.0);
  EXPECT_EQ(p.after_refit(100.5, {4.5, 100.0}), Choice::kRefit);
  EXPECT_EQ(p.after_refit(101.0, {17.8, 100.5}), Choice::kRefit);
  EXPECT_EQ(p.after_refit(101.5, {11.4, 101.0}), Choice::kRefit);
}

TEST(AutoUpdatePolicy, ExplosionRebuildsWithMortonEveryFrame) {
  // SAH build 250 ms; the queries take 80 ms on the fresh tree of SAH
  // cost 100; each frame's refit triples the cost, so the coming frame would
  // take 240 ms. Morton, not run yet, is estimated at a quarter of the time
  // for 20 % more time per ray: 96 + sqrt(2 * 62.5 * 160) a frame against
  // 80 + sqrt(2 * 250 * 160).
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kSah, 250.0, 100.0);
  EXPECT_EQ(p.after_refit(300.0, {80.0, 100.0}), Choice::kMorton);
  p.rebuilt(Choice::kMorton, 60.0, 125.0);
  for (int frame = 2; frame < 10; ++frame) {
    EXPECT_EQ(p.after_refit(375.0, {100.0, 125.0}), Choice::kMorton) << frame;
    p.rebuilt(Choice::kMorton, 60.0, 125.0);
  }
}

TEST(AutoUpdatePolicy, AFirstRebuildCountsAtMostTheEstimate) {
  // SAH 250 ms; the first Morton rebuild took 200 ms (its buffers faulted
  // in), counted as the estimate 62.5. The queries lose 25 ms in the
  // first frame and would lose 50 in the next: 75 >= 62.5, a Morton
  // rebuild (at 200 ms the SAH builder's period would be the cheaper, and
  // neither due).
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kSah, 250.0, 100.0);
  p.rebuilt(Choice::kMorton, 200.0, 120.0);
  EXPECT_EQ(p.after_refit(150.0, {100.0, 120.0}), Choice::kRefit);
  EXPECT_EQ(p.after_refit(180.0, {125.0, 150.0}), Choice::kMorton);
}

TEST(AutoUpdatePolicy, PrefersTheSahBuilderWhenItsBuildIsHardlyDearer) {
  // Measured: Morton 99 ms, SAH 100 ms; a Morton tree is taken to cost 20 %
  // more, so the SAH builder's period is cheaper.
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kMorton, 99.0, 120.0);
  p.rebuilt(Choice::kSah, 100.0, 100.0);
  EXPECT_EQ(p.after_refit(400.0, {100.0, 100.0}), Choice::kSah);
}

TEST(AutoUpdatePolicy, SlowGrowthRebuildsAtTheBestPeriod) {
  // SAH cost 100 growing 1 a frame; queries taking 1 ms per unit of
  // the cost of the tree they ran on, so frame j loses j ms; SAH builds of
  // 200 ms, Morton measured at 150 ms (its tree 20 % dearer: 120 +
  // sqrt(2 * 150) > 100 + sqrt(2 * 200) a frame): SAH, at the best period
  // sqrt(2 * 200 / 1) = 20 frames, where the lost time sum_{j=1..P} j, the
  // coming frame's included, first reaches 200.
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kMorton, 150.0, 130.0);
  p.rebuilt(Choice::kSah, 200.0, 100.0);
  int frame = 1;
  Choice c = Choice::kRefit;
  for (; frame < 100; ++frame) {
    const double cost = 100.0 + frame;
    c = p.after_refit(cost, {cost - 1.0, cost - 1.0});
    if (c != Choice::kRefit) break;
  }
  EXPECT_EQ(c, Choice::kSah);
  EXPECT_EQ(frame, 20);
  EXPECT_NEAR(std::sqrt(2.0 * 200.0 / 1.0), double(frame), 0.5);
}

// predicted_rebuild extrapolates the refitted cost along its growth since
// the last rebuild: on the slow growth above (linear, so exact) it says
// rebuild exactly on the frame after_refit would, and keep before; right
// after a rebuild (no growth measured in this period) and without timed
// queries it says refit, whatever the figures.
TEST(AutoUpdatePolicy, PredictedRebuildComesOnTheFrameTheRefitWouldChoose) {
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kMorton, 150.0, 130.0);
  p.rebuilt(Choice::kSah, 200.0, 100.0);
  EXPECT_EQ(p.predicted_rebuild({1.0e6, 100.0}), Choice::kRefit);  // no refit since the rebuild
  int frame = 1;
  Choice c = Choice::kRefit;
  for (; frame < 100; ++frame) {
    const double cost = 100.0 + frame;
    const AutoUpdatePolicy::Queries q{cost - 1.0, cost - 1.0};
    c = p.predicted_rebuild(q);
    if (c != Choice::kRefit) break;
    ASSERT_EQ(p.after_refit(cost, q), Choice::kRefit) << frame;
  }
  EXPECT_EQ(c, Choice::kSah);
  EXPECT_EQ(frame, 20);
  EXPECT_EQ(p.predicted_rebuild({}), Choice::kRefit);             // nothing queried
  EXPECT_EQ(p.predicted_rebuild({0.0, 5000.0}), Choice::kRefit);  // nothing timed
  EXPECT_EQ(p.predicted_rebuild({1.0e6, 119.0}), Choice::kSah);
}

TEST(AutoUpdatePolicy, AMortonOnlyConfigurationRebuildsWithMorton) {
  AutoUpdatePolicy p(false, 1.3);
  p.rebuilt(Choice::kMorton, 50.0, 120.0);
  EXPECT_EQ(p.after_refit(1000.0, {100.0, 120.0}), Choice::kMorton);
  EXPECT_EQ(p.forced_rebuild(), Choice::kMorton);
}

TEST(AutoUpdatePolicy, ForcedRebuildWithoutQueriesTakesTheCheaperBuild) {
  AutoUpdatePolicy p(true, 1.3);
  p.rebuilt(Choice::kSah, 250.0, 100.0);
  EXPECT_EQ(p.forced_rebuild(), Choice::kMorton);  // estimated 62.5 ms
  p.rebuilt(Choice::kMorton, 300.0, 120.0);        // a first run: counts 62.5
  EXPECT_EQ(p.forced_rebuild(), Choice::kMorton);
  p.rebuilt(Choice::kMorton, 300.0, 120.0);  // measured slower than SAH
  EXPECT_EQ(p.forced_rebuild(), Choice::kSah);
}

}  // namespace
}  // namespace hprt
