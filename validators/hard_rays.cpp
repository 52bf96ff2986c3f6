// Hard ray sets (see hard_rays.h).
#include "validators/hard_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/error.h"
#include "workload/sampling.h"

namespace hprt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Uniform choice of a triangle over a set of meshes: prefix sums of their
// triangle counts.
class TrianglePicker {
 public:
  TrianglePicker(const Scene& scene, std::vector<uint32_t> meshes) : scene_(scene) {
    size_t total = 0;
    for (uint32_t m : meshes) {
      if (scene.meshes[m].triangles.empty()) continue;
      total += scene.meshes[m].triangles.size();
      meshes_.push_back(m);
      ends_.push_back(total);
    }
  }
  bool empty() const { return ends_.empty(); }
  // (mesh, triangle) of a uniformly chosen triangle that can be hit.
  std::pair<uint32_t, uint32_t> pick(SplitMix64& rng, const char* kind) const {
    for (int attempt = 0; attempt < 1000; ++attempt) {
      const size_t g = rng.below(ends_.back());
      const size_t k = size_t(std::upper_bound(ends_.begin(), ends_.end(), g) - ends_.begin());
      const size_t first = k == 0 ? 0 : ends_[k - 1];
      const uint32_t mesh = meshes_[k];
      const uint32_t tri = uint32_t(g - first);
      if (scene_.meshes[mesh].triangle_valid(tri)) return {mesh, tri};
    }
    throw OptionError("kind", std::string(kind) + ": found no valid (non-degenerate) triangle");
  }

 private:
  const Scene& scene_;
  std::vector<uint32_t> meshes_;
  std::vector<size_t> ends_;
};

std::vector<uint32_t> all_meshes(const Scene& scene) {
  std::vector<uint32_t> v(scene.meshes.size());
  for (uint32_t i = 0; i < v.size(); ++i) v[i] = i;
  return v;
}

// Closed = every undirected edge is used by exactly two triangles.
bool mesh_closed(const TriangleMesh& m) {
  if (m.triangles.empty()) return false;
  std::vector<uint64_t> edges;
  edges.reserve(m.triangles.size() * 3);
  for (const Vec3u& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = t[k], b = t[(k + 1) % 3];
      if (a == b) return false;
      edges.push_back(a < b ? (a << 32 | b) : (b << 32 | a));
    }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) return false;
    i = j;
  }
  return true;
}

Vec3f mesh_centroid(const TriangleMesh& m) {
  Vec3d sum(0.0);
  for (const Vec3f& p : m.positions) sum += Vec3d(p);
  return Vec3f(sum / double(m.positions.size()));
}

void require_triangles(const TrianglePicker& picker, const char* kind) {
  if (picker.empty())
    throw OptionError("kind", std::string(kind) + " rays need a scene with triangles");
}

}  // namespace

// From a closed mesh's centroid at one of its vertices or edge midpoints.
std::vector<Ray> probe_rays(const Scene& scene, size_t n, SplitMix64& rng, bool at_vertex) {
  const std::string kind = at_vertex ? "vertex-probe" : "edge-probe";
  std::vector<uint32_t> closed;
  for (uint32_t i = 0; i < scene.meshes.size(); ++i)
    if (mesh_closed(scene.meshes[i])) closed.push_back(i);
  if (closed.empty())
    throw OptionError("kind",
                      kind + " rays need a closed mesh (every edge shared by two triangles)");
  std::vector<Vec3f> centroids(scene.meshes.size());
  for (uint32_t m : closed) centroids[m] = mesh_centroid(scene.meshes[m]);
  const TrianglePicker picker(scene, closed);
  std::vector<Ray> rays;
  rays.reserve(n);
  size_t attempts = 0;
  while (rays.size() < n) {
    if (++attempts > 100 * n + 1000)
      throw OptionError("kind", kind + ": every target is the centroid");
    const auto [mesh, tri] = picker.pick(rng, "probe");
    const TriangleMesh& m = scene.meshes[mesh];
    const int k = int(rng.below(3));
    const Vec3f a = m.positions[m.triangles[tri][k]];
    const Vec3f target = at_vertex ? a : (a + m.positions[m.triangles[tri][(k + 1) % 3]]) * 0.5f;
    Ray r;
    r.org = centroids[mesh];
    r.dir = target - r.org;  // unnormalised: the target sits at t = 1
    if (r.dir == Vec3f(0.0f)) continue;
    rays.push_back(r);
  }
  return rays;
}

std::vector<Ray> grazing_rays(const Scene& scene, size_t n, SplitMix64& rng) {
  const TrianglePicker picker(scene, all_meshes(scene));
  require_triangles(picker, "grazing");
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    const auto [mesh, tri] = picker.pick(rng, "grazing");
    const TriangleMesh& m = scene.meshes[mesh];
    const Vec3f a = m.positions[m.triangles[tri][0]], b = m.positions[m.triangles[tri][1]],
                c = m.positions[m.triangles[tri][2]];
    const Vec3d nd = normalize(cross(Vec3d(b - a), Vec3d(c - a)));
    // In-plane direction: a random direction with its normal part removed.
    Vec3d t;
    do {
      const Vec3d s(uniform_sphere(rng));
      t = s - nd * dot(s, nd);
    } while (length(t) < 1e-3);
    t = normalize(t);
    // Normal component 1e-4 .. 1e-7 (log-uniform), either sign.
    const double eps = std::pow(10.0, -4.0 - 3.0 * rng.uniform()) * (rng.coin() ? 1.0 : -1.0);
    const Vec3d dir = normalize(t + nd * eps);
    const Vec3d centre = (Vec3d(a) + Vec3d(b) + Vec3d(c)) / 3.0;
    const double edge =
        std::max({length(Vec3d(b - a)), length(Vec3d(c - b)), length(Vec3d(a - c))});
    r.org = Vec3f(centre - dir * (2.0 * edge));
    r.dir = Vec3f(dir);
  }
  return rays;
}

// Axis-parallel rays through mesh vertices: the axis component is exactly ±1
// and the others exactly +0 or -0 (both signs occur). Half start exactly on
// the scene box's plane, half 10% of the box outside it.
std::vector<Ray> axis_rays(const Scene& scene, size_t n, SplitMix64& rng) {
  const TrianglePicker picker(scene, all_meshes(scene));
  require_triangles(picker, "axis");
  const AABB box = scene_box_or_unit(scene);
  const Vec3f margin = box.diagonal() * 0.1f;
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    const auto [mesh, tri] = picker.pick(rng, "axis");
    const TriangleMesh& m = scene.meshes[mesh];
    const Vec3f v = m.positions[m.triangles[tri][rng.below(3)]];
    const int axis = int(rng.below(3));
    const bool positive = rng.coin();
    for (int k = 0; k < 3; ++k) r.dir[k] = rng.coin() ? 0.0f : -0.0f;
    r.dir[axis] = positive ? 1.0f : -1.0f;
    r.org = v;
    const bool on_plane = rng.coin();
    r.org[axis] = positive ? (on_plane ? box.min[axis] : box.min[axis] - margin[axis])
                           : (on_plane ? box.max[axis] : box.max[axis] + margin[axis]);
  }
  return rays;
}

// Rays that would hit the scene's centre if they were valid, each broken in
// one of ten ways; every one must miss (intersector.h: invalid rays miss).
std::vector<Ray> nan_rays(const Scene& scene, size_t n, SplitMix64& rng) {
  const AABB box = scene_box_or_unit(scene);
  const Vec3f c = box.center(), half = box.diagonal() * 0.55f;
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    Ray& r = rays[i];
    r.org = c + uniform_sphere(rng) * (2.0f * length(half) + 1.0f);
    r.dir = c - r.org;
    const int k = int(rng.below(3));
    switch (i % 10) {
      case 0:
        r.org[k] = kNaN;
        break;
      case 1:
        r.dir[k] = kNaN;
        break;
      case 2:
        r.dir[k] = rng.coin() ? kInf : -kInf;
        break;
      case 3:
        r.dir = Vec3f(0.0f);
        break;
      case 4:
        r.dir = Vec3f(-0.0f);
        break;
      case 5:
        r.tnear = 2.0f;
        r.tfar = 1.0f;
        break;
      case 6:
        r.tnear = kNaN;
        break;
      case 7:
        r.tfar = kNaN;
        break;
      case 8:
        r.tnear = -1.0f;
        break;   // segment starting behind the origin
      case 9: {  // finite, but a component above Embree's FLT_LARGE (1.844e18)
        const float big = std::max({std::fabs(r.dir.x), std::fabs(r.dir.y), std::fabs(r.dir.z)});
        r.dir = r.dir * (1e19f / big);
        break;
      }
    }
  }
  return rays;
}

}  // namespace hprt
