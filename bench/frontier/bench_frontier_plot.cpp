// Pareto marking and the gnuplot child process (posix_spawnp, no shell).
#include "bench/frontier/bench_frontier_plot.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <system_error>

extern char** environ;

namespace hprt::bench {

void mark_pareto(std::vector<FrontierPoint>& points) {
  for (auto& p : points) {
    p.pareto = true;
    for (const auto& q : points) {
      const bool no_worse = q.mrays_per_s >= p.mrays_per_s && q.wrong_rays <= p.wrong_rays;
      const bool better = q.mrays_per_s > p.mrays_per_s || q.wrong_rays < p.wrong_rays;
      if (&q != &p && no_worse && better) {
        p.pareto = false;
        break;
      }
    }
  }
}

namespace {

std::string quote_gnuplot(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// Runs `gnuplot script`; returns its exit status, or -1 when it cannot start.
int run_gnuplot(const std::string& script) {
  pid_t pid = 0;
  std::string prog = "gnuplot";
  char* argv[] = {prog.data(), const_cast<char*>(script.c_str()), nullptr};
  if (posix_spawnp(&pid, "gnuplot", nullptr, nullptr, argv, environ) != 0) return -1;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

PlotResult write_frontier_plot(const std::vector<FrontierPoint>& points, const std::string& dir,
                               const std::string& mesh_label) {
  namespace fs = std::filesystem;
  PlotResult r;
  const fs::path base = fs::path(dir);
  const std::string tag = ".tmp-" + std::to_string(::getpid());
  const fs::path data = base / ("frontier" + tag + ".dat");
  const fs::path front = base / ("frontier" + tag + "-front.dat");
  const fs::path labels = base / ("frontier" + tag + "-labels.dat");
  const fs::path script = base / ("frontier" + tag + ".gp");
  const fs::path png_tmp = base / ("frontier" + tag + ".png");
  const fs::path png = base / "frontier.png";
  auto cleanup = [&] {
    std::error_code ec;
    for (const auto& p : {data, front, labels, script, png_tmp}) fs::remove(p, ec);
  };
  {
    std::ofstream d(data), f(front), l(labels), g(script);
    if (!d || !f || !l || !g) {
      cleanup();
      r.message = "cannot write temporary files in " + dir;
      return r;
    }
    // columns: wrong rays, Mrays/s, label, pareto, default
    for (const auto& p : points)
      d << p.wrong_rays << ' ' << p.mrays_per_s << ' ' << quote_gnuplot(p.name) << ' '
        << (p.pareto ? 1 : 0) << ' ' << (p.is_default ? 1 : 0) << '\n';
    std::vector<size_t> idx(points.size());
    std::iota(idx.begin(), idx.end(), 0);
    std::sort(idx.begin(), idx.end(),
              [&](size_t a, size_t b) { return points[a].wrong_rays < points[b].wrong_rays; });
    for (size_t i : idx)
      if (points[i].pareto) f << points[i].wrong_rays << ' ' << points[i].mrays_per_s << '\n';
    // Labels: the front and the default first, then any point not within a
    // few percent of an already labelled one (clusters get one label).
    double xr = 1e-9, yr = 1e-9;
    for (const auto& p : points) {
      xr = std::max(xr, p.wrong_rays);
      yr = std::max(yr, p.mrays_per_s);
    }
    std::vector<size_t> order(points.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return (points[a].pareto || points[a].is_default) >
             (points[b].pareto || points[b].is_default);
    });
    std::vector<size_t> labelled;
    for (size_t i : order) {
      const bool near = std::any_of(labelled.begin(), labelled.end(), [&](size_t j) {
        return std::abs(points[i].wrong_rays - points[j].wrong_rays) < 0.04 * xr &&
               std::abs(points[i].mrays_per_s - points[j].mrays_per_s) < 0.04 * yr;
      });
      if (near && !points[i].pareto && !points[i].is_default) continue;
      const int others = int(std::count_if(points.begin(), points.end(), [&](const auto& q) {
        return &q != &points[i] && std::abs(q.wrong_rays - points[i].wrong_rays) < 0.04 * xr &&
               std::abs(q.mrays_per_s - points[i].mrays_per_s) < 0.04 * yr;
      }));
      labelled.push_back(i);
      std::string text = points[i].name;
      if (points[i].is_default) text += " (default)";
      if (others > 0 && !near) text += " (+" + std::to_string(others) + " near)";
      l << points[i].wrong_rays << ' ' << points[i].mrays_per_s << ' ' << quote_gnuplot(text) << ' '
        << labelled.size() << '\n';
    }
    g << "set terminal pngcairo size 900,600 noenhanced font 'sans,9'\n"
      << "set output " << quote_gnuplot(png_tmp.string()) << "\n"
      << "set title " << quote_gnuplot("hprt frontier: speed against error (" + mesh_label + ")")
      << "\n"
      << "set xlabel 'hard-case rays wrong per the exact arbiter'\n"
      << "set ylabel 'trace Mrays/s (primary + random, closest hit)'\n"
      << "set grid\nset key top left box opaque\nset offsets graph 0.05, graph 0.3, graph 0.1, "
         "graph 0.08\nset yrange [0:*]\n"
      << "plot " << quote_gnuplot(front.string())
      << " using 1:2 with steps lw 2 lc rgb '#d62728' title 'Pareto front', \\\n"
      << "  " << quote_gnuplot(data.string())
      << " using 1:($4==1?$2:1/0) with points pt 7 ps 1.4 lc rgb '#d62728' title 'on the front', "
         "\\\n"
      << "  '' using 1:($4==0?$2:1/0) with points pt 6 ps 1.2 lc rgb '#1f77b4' title 'dominated', "
         "\\\n"
      << "  '' using 1:($5==1?$2:1/0) with points pt 4 ps 2.5 lw 2 lc rgb 'black' title "
         "'default', \\\n"
      << "  " << quote_gnuplot(labels.string())
      << " using 1:2:3 with labels left offset 1,0.5 font 'sans,7' notitle\n";
  }
  const int status = run_gnuplot(script.string());
  std::error_code ec;
  if (status != 0 || !fs::exists(png_tmp, ec)) {
    cleanup();
    r.message = status == -1 ? "gnuplot not found (install it: scripts/setup.sh)"
                             : "gnuplot failed (exit " + std::to_string(status) + ")";
    return r;
  }
  fs::rename(png_tmp, png, ec);
  cleanup();
  if (ec) {
    r.message = "cannot rename the plot: " + ec.message();
    return r;
  }
  r.written = true;
  r.path = png.string();
  return r;
}

}  // namespace hprt::bench
