// The `auto` update strategy (UpdateStrategy::kAuto, the default): after
// each refit, whether to keep the refitted tree or rebuild it with the fast
// Morton builder or with the configured SAH builder, from what the backend
// measured, so that an animation gets the cheaper path without flags.
//
// Model, all in measured milliseconds: a frame's queries take n rays x m,
// m the time per ray, which grows as the refitted tree degrades. A rebuild
// with builder b costs R_b (its last measured rebuild) and brings m back to
// M_b (the time per ray in the first frame after that rebuild). If the
// frame's lost time n (m - M_b) grows by g a frame, rebuilding with b every
// P frames costs R_b / P + n M_b + g (P - 1) / 2 a frame, least at
// P = sqrt(2 R_b / g): exactly the frame at which the time lost since the
// last rebuild reaches R_b. So the policy keeps b = the builder whose best
// period is cheaper (n M_b + sqrt(2 R_b g)) and rebuilds with it once its
// lost time, the coming frame's included, reaches R_b (the ski-rental rule:
// where the growth is not linear it is never worse than twice the best
// choice in hindsight). The coming frame's time per ray is the last one's
// scaled by the SAH cost the refit just gave the tree, the one prediction
// the SAH is used for.
//
// Estimates where nothing is measured: the builder that did not make the
// last tree is taken to trace kMortonCostRatio slower (Morton) or faster
// (SAH) per ray, and one never run to build in kMortonBuildShare (Morton)
// or 1 / kMortonBuildShare (SAH) of the other's time. A builder's first
// rebuild also faults in its buffers, which later rebuilds reuse, so its
// first time counts at most that estimate. When the first frame
// after a rebuild ran no queries, M is scaled from a later frame by the SAH
// costs of the two trees. Frames without queries lose nothing, so they only
// refit; until any query has been timed the rule is `adaptive`'s (rebuild
// past prior_factor times the last rebuild's SAH cost), with the cheaper
// build.
#pragma once

#include <cstdint>

namespace hprt {

class AutoUpdatePolicy {
 public:
  enum class Choice { kRefit, kMorton, kSah };

  // From bench build's 1M-triangle meshes: a Morton build takes about a
  // quarter of a binned SAH build (prim info and layout included), for a
  // tree about 20 % slower to trace.
  static constexpr double kMortonBuildShare = 0.25;
  static constexpr double kMortonCostRatio = 1.2;

  // sah_available: the configured builder is an SAH one (else every rebuild
  // is a Morton one); prior_factor: the rule before any query was timed.
  AutoUpdatePolicy(bool sah_available, double prior_factor)
      : sah_available_(sah_available), prior_factor_(prior_factor) {}

  // After a build or rebuild with `which`: its time and its tree's SAH cost.
  void rebuilt(Choice which, double ms, double sah_cost);

  // The queries since the last update: busy ms, rays (and points), and the
  // SAH cost of the tree they ran on.
  struct Queries {
    double ms = 0.0;
    uint64_t rays = 0;
    double sah_cost = 0.0;
  };
  // After a valid refit to SAH cost `refit_cost`.
  Choice after_refit(double refit_cost, const Queries& q);

  // A rebuild that must happen (the tree cannot be refitted): the builder
  // with the cheaper period by the last measurements.
  Choice forced_rebuild() const;

 private:
  struct Builder {
    double ms = -1.0;      // last rebuild's time; < 0: not run yet
    double lost_ms = 0.0;  // query time lost to the refitted tree since the last rebuild
  };
  Builder& of(Choice c) { return c == Choice::kMorton ? morton_ : sah_; }
  double build_ms(Choice c) const;
  double fresh_ms_per_ray(Choice c) const;
  // Per-frame cost of rebuilding with c at its best period.
  double period_cost(Choice c) const;
  Choice cheaper() const;

  bool sah_available_;
  double prior_factor_;
  bool timed_ = false;  // some query was timed
  Builder morton_, sah_;
  Choice last_ = Choice::kSah;  // the last rebuild's builder
  int frames_since_rebuild_ = 0;
  double cost_after_rebuild_ = 0.0;
  double fresh_ms_per_ray_ = -1.0;  // M of the last rebuild's tree; < 0: not known yet
  double rays_ = 0.0;               // rays of the last timed frame
  double growth_ = 0.0;             // g: lost ms a frame added per frame
};

}  // namespace hprt
