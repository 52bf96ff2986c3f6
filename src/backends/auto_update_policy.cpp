#include "backends/auto_update_policy.h"

#include <algorithm>
#include <cmath>

namespace hprt {

void AutoUpdatePolicy::rebuilt(Choice which, double ms, double sah_cost) {
  if (which == Choice::kRefit) return;
  Builder& b = of(which);
  const double estimate = build_ms(which);  // from the other builder; 0: none
  b.ms = b.ms < 0.0 && estimate > 0.0 ? std::min(ms, estimate) : ms;
  last_ = which;
  morton_.lost_ms = sah_.lost_ms = 0.0;
  frames_since_rebuild_ = 0;
  cost_after_rebuild_ = sah_cost;
  fresh_ms_per_ray_ = -1.0;
}

double AutoUpdatePolicy::build_ms(Choice c) const {
  const Builder& b = c == Choice::kMorton ? morton_ : sah_;
  if (b.ms >= 0.0) return b.ms;
  const Builder& other = c == Choice::kMorton ? sah_ : morton_;
  if (other.ms < 0.0) return 0.0;
  return c == Choice::kMorton ? other.ms * kMortonBuildShare : other.ms / kMortonBuildShare;
}

double AutoUpdatePolicy::fresh_ms_per_ray(Choice c) const {
  if (c == last_) return fresh_ms_per_ray_;
  return c == Choice::kMorton ? fresh_ms_per_ray_ * kMortonCostRatio
                              : fresh_ms_per_ray_ / kMortonCostRatio;
}

double AutoUpdatePolicy::period_cost(Choice c) const {
  return rays_ * std::max(0.0, fresh_ms_per_ray(c)) + std::sqrt(2.0 * build_ms(c) * growth_);
}

AutoUpdatePolicy::Choice AutoUpdatePolicy::cheaper() const {
  if (!sah_available_) return Choice::kMorton;
  const double m = period_cost(Choice::kMorton), s = period_cost(Choice::kSah);
  if (m != s) return m < s ? Choice::kMorton : Choice::kSah;
  return build_ms(Choice::kMorton) <= build_ms(Choice::kSah) ? Choice::kMorton : Choice::kSah;
}

AutoUpdatePolicy::Choice AutoUpdatePolicy::after_refit(double refit_cost, const Queries& q) {
  ++frames_since_rebuild_;
  if (!(q.ms > 0.0 && q.rays > 0)) {  // nothing queried: nothing lost this frame
    if (timed_) return Choice::kRefit;
    return refit_cost > prior_factor_ * cost_after_rebuild_ ? cheaper() : Choice::kRefit;
  }
  timed_ = true;
  rays_ = double(q.rays);
  const double ms_per_ray = q.ms / rays_;
  if (fresh_ms_per_ray_ < 0.0) {
    // The first timed frame since the rebuild: its tree was the fresh one,
    // or (a frame without queries came between) a refit of it.
    fresh_ms_per_ray_ = frames_since_rebuild_ == 1 || !(q.sah_cost > 0.0)
                            ? ms_per_ray
                            : ms_per_ray * cost_after_rebuild_ / q.sah_cost;
  }
  // The coming frame's time per ray on the refitted tree: this frame's,
  // scaled by the change of SAH cost the refit just made.
  const double next_ms_per_ray =
      q.sah_cost > 0.0 ? ms_per_ray * refit_cost / q.sah_cost : ms_per_ray;
  growth_ = std::max(0.0, rays_ * (next_ms_per_ray - fresh_ms_per_ray_)) / frames_since_rebuild_;
  Choice best = cheaper();
  double due = 0.0;  // time lost by the coming frame, if it keeps the refitted tree
  for (Choice c : {Choice::kMorton, Choice::kSah}) {
    Builder& b = of(c);
    b.lost_ms = std::max(0.0, b.lost_ms + rays_ * (ms_per_ray - fresh_ms_per_ray(c)));
    if (c == best) due = b.lost_ms + rays_ * (next_ms_per_ray - fresh_ms_per_ray(c));
  }
  return due > 0.0 && due >= build_ms(best) ? best : Choice::kRefit;
}

AutoUpdatePolicy::Choice AutoUpdatePolicy::forced_rebuild() const { return cheaper(); }

}  // namespace hprt
