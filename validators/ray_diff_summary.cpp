#include "validators/ray_diff_summary.h"

#include <cstdio>

namespace hprt {

std::string ray_diff_summary(const RayDiffResult& r, const RayDiffLabels& l) {
  std::string out;
  char line[512];
  auto add = [&](const char* text) { out += text; };
  std::snprintf(line, sizeof line, "hprt validate rays: %s vs %s, %s, %zu rays (%s)%s\n",
                l.backend.c_str(), l.reference.c_str(), l.occluded ? "occluded" : "closest hit",
                r.rays, l.source.c_str(), r.brute_force ? ", arbiter over all triangles" : "");
  add(line);
  auto row = [&](const std::string& name, size_t v) {
    std::snprintf(line, sizeof line, "  %-22s %12zu  %7.3f%%\n", name.c_str(), v,
                  r.rays ? 100.0 * double(v) / double(r.rays) : 0.0);
    add(line);
  };
  row("agree", r.agree);
  row("ties", r.ties);
  row("mismatches", r.mismatches);
  row(" backend right", r.bvh_right);
  row(" reference right", r.embree_right);
  row(" both right", r.both_right);
  row(" both wrong", r.both_wrong);
  if (r.bvh_malformed || r.embree_malformed) {
    row("malformed (backend)", r.bvh_malformed);
    row("malformed (reference)", r.embree_malformed);
  }
  std::snprintf(line, sizeof line,
                "  max rel t error: %.3g (agreeing), %.3g (backend vs arbiter)\n",
                r.max_rel_t_error, r.max_rel_t_error_arbiter);
  add(line);
  std::snprintf(line, sizeof line, "  %s wrong on %zu rays: %s%s%s\n", l.backend.c_str(),
                r.bvh_wrong(), r.bvh_wrong() ? "FAIL" : "pass",
                l.mismatches.empty() ? "" : "; mismatches -> ", l.mismatches.c_str());
  add(line);
  return out;
}

}  // namespace hprt
