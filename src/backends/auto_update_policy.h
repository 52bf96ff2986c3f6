// The `auto` update strategy (UpdateStrategy::kAuto, the default): after
// each refit, whether to keep the refitted tree or rebuild it with the fast
// Morton builder or with the configured SAH builder, from what the backend
// measured, so that an animation gets the cheaper path without flags.
//
// Model: a frame's query time divided by the SAH cost of the tree it ran
// on gives k, ms per unit of cost, measured afresh every frame, so a busier
// machine or more rays change k, not the share of the time that the tree's
// degradation explains. A rebuild with builder b costs R_b (its last
// measured rebuild) and gives a tree of cost F_b (the last rebuild's cost,
// scaled by kMortonCostRatio for the other builder: the cost of a fresh
// tree follows the moving geometry, so an older figure says little). If
// the refitted tree's cost grows so that a frame loses k (c - F_b) ms, and
// that loss grows by g a frame, rebuilding with b every P frames costs
// R_b / P + k F_b + g (P - 1) / 2 a frame, least at P = sqrt(2 R_b / g):
// exactly the frame at which the time lost since the last rebuild reaches
// R_b. So the policy keeps b = the builder whose best period is cheaper
// (k F_b + sqrt(2 R_b g)) and rebuilds with it once its lost time, the
// coming frame's included, reaches R_b (the ski-rental rule: where the
// growth is not linear it is never worse than twice the best choice in
// hindsight).
//
// A builder never run is estimated to build in kMortonBuildShare (Morton)
// or 1 / kMortonBuildShare (SAH) of the other's time; its first rebuild
// also faults in its buffers, which later rebuilds reuse, so that first
// time counts at most the estimate. Frames without queries lose nothing,
// so they only refit; until any query has been timed the rule is
// `adaptive`'s (rebuild past prior_factor times the last rebuild's SAH
// cost), with the cheaper build.
#pragma once

namespace hprt {

class AutoUpdatePolicy {
 public:
  enum class Choice { kRefit, kMorton, kSah };

  // From bench build's 1M-triangle meshes: a Morton build takes about a
  // quarter of a binned SAH build (prim info and layout included), for a
  // tree of about 20 % more SAH cost.
  static constexpr double kMortonBuildShare = 0.25;
  static constexpr double kMortonCostRatio = 1.2;

  // sah_available: the configured builder is an SAH one (else every rebuild
  // is a Morton one); prior_factor: the rule before any query was timed.
  AutoUpdatePolicy(bool sah_available, double prior_factor)
      : sah_available_(sah_available), prior_factor_(prior_factor) {}

  // After a build or rebuild with `which`: its time and its tree's SAH cost.
  void rebuilt(Choice which, double ms, double sah_cost);

  // The queries since the last update: their busy ms and the SAH cost of
  // the tree they ran on.
  struct Queries {
    double ms = 0.0;
    double sah_cost = 0.0;
  };
  // After a valid refit to SAH cost `refit_cost`.
  Choice after_refit(double refit_cost, const Queries& q);

  // Before refitting: the rebuild after_refit would choose if the refit
  // continued the cost's growth since the last rebuild in a straight line,
  // else kRefit. A rebuild frame then skips its refit. Only once this
  // period has refitted and timed queries (q is of a refitted tree), so a
  // rebuild is always followed by a refit that measures the growth anew
  // and a scene that stops moving stops rebuilding.
  Choice predicted_rebuild(const Queries& q) const;

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
  double fresh_cost(Choice c) const;
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
  double ms_per_cost_ = 0.0;  // k of the last timed frame
  double growth_ = 0.0;       // g: lost ms a frame added per frame
};

}  // namespace hprt
