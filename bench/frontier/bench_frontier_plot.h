// The frontier plot: speed (Mrays/s) against error (wrong hard-case rays),
// every configuration labelled, the Pareto front drawn as a step line and
// the default configuration marked. gnuplot as a child process.
#pragma once

#include <string>
#include <vector>

namespace hprt::bench {

struct FrontierPoint {
  std::string name;
  double mrays_per_s = 0.0;
  double wrong_rays = 0.0;
  bool is_default = false;
  bool pareto = false;  // set by mark_pareto
};

// A point is on the front when no other point is at least as fast with at
// most as many wrong rays and strictly better in one of the two.
void mark_pareto(std::vector<FrontierPoint>& points);

struct PlotResult {
  bool written = false;
  std::string path;     // <dir>/frontier.png when written
  std::string message;  // why not, otherwise (gnuplot missing or failed)
};

// Writes <dir>/frontier.png (pngcairo, 900x600): the data and script go to
// temporary files in `dir`, gnuplot renders to a temporary PNG which is then
// renamed, so no partial plot is left. Never throws for a missing gnuplot.
PlotResult write_frontier_plot(const std::vector<FrontierPoint>& points, const std::string& dir,
                               const std::string& mesh_label);

}  // namespace hprt::bench
