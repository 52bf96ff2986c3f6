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
}

double AutoUpdatePolicy::build_ms(Choice c) const {
  const Builder& b = c == Choice::kMorton ? morton_ : sah_;
  if (b.ms >= 0.0) return b.ms;
  const Builder& other = c == Choice::kMorton ? sah_ : morton_;
  if (other.ms < 0.0) return 0.0;
  return c == Choice::kMorton ? other.ms * kMortonBuildShare : other.ms / kMortonBuildShare;
}

double AutoUpdatePolicy::fresh_cost(Choice c) const {
  if (c == last_) return cost_after_rebuild_;
  return c == Choice::kMorton ? cost_after_rebuild_ * kMortonCostRatio
                              : cost_after_rebuild_ / kMortonCostRatio;
}

double AutoUpdatePolicy::period_cost(Choice c) const {
  return ms_per_cost_ * fresh_cost(c) + std::sqrt(2.0 * build_ms(c) * growth_);
}

AutoUpdatePolicy::Choice AutoUpdatePolicy::cheaper() const {
  if (!sah_available_) return Choice::kMorton;
  const double m = period_cost(Choice::kMorton), s = period_cost(Choice::kSah);
  if (m != s) return m < s ? Choice::kMorton : Choice::kSah;
  return build_ms(Choice::kMorton) <= build_ms(Choice::kSah) ? Choice::kMorton : Choice::kSah;
}

AutoUpdatePolicy::Choice AutoUpdatePolicy::after_refit(double refit_cost, const Queries& q) {
  ++frames_since_rebuild_;
  const double cost = q.sah_cost > 0.0 ? q.sah_cost : refit_cost;  // of the tree queried
  if (!(q.ms > 0.0 && cost > 0.0)) {                               // nothing queried: nothing lost
    if (timed_) return Choice::kRefit;
    return refit_cost > prior_factor_ * cost_after_rebuild_ ? cheaper() : Choice::kRefit;
  }
  timed_ = true;
  ms_per_cost_ = q.ms / cost;
  growth_ =
      std::max(0.0, ms_per_cost_ * (refit_cost - cost_after_rebuild_)) / frames_since_rebuild_;
  const Choice best = cheaper();
  double due = 0.0;  // time lost by the coming frame too, if it keeps the refitted tree
  for (Choice c : {Choice::kMorton, Choice::kSah}) {
    Builder& b = of(c);
    b.lost_ms += std::max(0.0, ms_per_cost_ * (cost - fresh_cost(c)));
    if (c == best) due = b.lost_ms + ms_per_cost_ * (refit_cost - fresh_cost(c));
  }
  return due > 0.0 && due >= build_ms(best) ? best : Choice::kRefit;
}

AutoUpdatePolicy::Choice AutoUpdatePolicy::predicted_rebuild(const Queries& q) const {
  if (frames_since_rebuild_ < 1 || !(q.ms > 0.0 && q.sah_cost > 0.0)) return Choice::kRefit;
  const double rate = (q.sah_cost - cost_after_rebuild_) / frames_since_rebuild_;
  AutoUpdatePolicy next = *this;  // the decision without its bookkeeping
  return next.after_refit(q.sah_cost + rate, q);
}

AutoUpdatePolicy::Choice AutoUpdatePolicy::forced_rebuild() const { return cheaper(); }

}  // namespace hprt
