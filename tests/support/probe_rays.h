// Rays aimed exactly at every vertex and at the float midpoint of every edge
// of a mesh: the hard cases of the watertight test and of crossing counts.
#pragma once

#include <algorithm>
#include <set>
#include <utility>
#include <vector>

#include "core/ray.h"
#include "core/triangle_mesh.h"

namespace hprt::test {

// `from(target)` gives each ray's origin; the direction is target - origin.
template <typename From>
std::vector<Ray> aimed_at_vertices_and_edges(const TriangleMesh& m, From from) {
  std::vector<Ray> rays;
  auto add = [&](Vec3f target) {
    Ray r;
    r.org = from(target);
    r.dir = target - r.org;
    rays.push_back(r);
  };
  for (const Vec3f& p : m.positions) add(p);
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (const Vec3u& t : m.triangles)
    for (int k = 0; k < 3; ++k) edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
  for (const auto& [a, b] : edges) add((m.positions[a] + m.positions[b]) * 0.5f);
  return rays;
}

}  // namespace hprt::test
