// Ray-set generators (see ray_sets.h). All randomness comes from a splitmix64
// stream seeded by the caller, so a set is bit-identical for a given seed on
// any platform (no std:: distributions, whose results are library-defined).
#include "ray_sets.h"  // validators/ is on the include path of users only
#include "core/ray_offset.h"
#include "core/splitmix64.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "core/camera.h"
#include "core/error.h"

namespace hprt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct KindName {
  RayKind kind;
  const char* name;
};
constexpr std::array<KindName, 9> kKinds{{{RayKind::kPrimary, "primary"},
                                          {RayKind::kShadow, "shadow"},
                                          {RayKind::kReflection, "reflection"},
                                          {RayKind::kRandom, "random"},
                                          {RayKind::kVertexProbe, "vertex-probe"},
                                          {RayKind::kEdgeProbe, "edge-probe"},
                                          {RayKind::kGrazing, "grazing"},
                                          {RayKind::kAxis, "axis"},
                                          {RayKind::kNan, "nan"}}};

using Rng = SplitMix64;

Vec3f uniform_sphere(Rng& rng) {
  const float z = 1.0f - 2.0f * rng.uniform();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * std::numbers::pi_v<float> * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

AABB scene_box(const Scene& scene) {
  AABB b = scene.bounds();
  if (b.empty()) b = AABB(Vec3f(-1.0f), Vec3f(1.0f));
  return b;
}

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
  std::pair<uint32_t, uint32_t> pick(Rng& rng, const char* kind) const {
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

void require_triangles(const TrianglePicker& picker, RayKind kind) {
  if (picker.empty())
    throw OptionError("kind", std::string(to_string(kind)) + " rays need a scene with triangles");
}

// Scanline-ordered, stratified-jittered camera rays: ray i lands in pixel
// floor((i + u) * W * H / n), so the set is coherent like a render's.
std::vector<Ray> primary_rays(const Scene& scene, size_t n, Rng& rng) {
  const CameraRays cam(scene.camera);
  const double pixels = double(cam.width()) * cam.height();
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    double p = std::floor((double(i) + rng.uniform()) * pixels / double(n));
    p = std::min(p, pixels - 1.0);
    const double y = std::floor(p / cam.width());
    const double x = p - y * cam.width();
    rays[i] = cam.ray(float(x) + rng.uniform(), float(y) + rng.uniform());
  }
  return rays;
}

// Primary hits for shadow and reflection rays: surface point rebuilt from the
// barycentrics (more accurate than org + t dir), unit geometric normal facing
// the incoming ray, and the incoming ray itself.
struct SurfaceHit {
  Vec3f p;
  Vec3f n;
  Vec3f dir;
};

std::vector<SurfaceHit> primary_hits(const Scene& scene, size_t n, Rng& rng,
                                     const Intersector* backend, RayKind kind) {
  if (!backend) throw std::invalid_argument(std::string(to_string(kind)) + " rays need a backend");
  std::vector<SurfaceHit> out;
  out.reserve(n);
  std::vector<Hit> hits;
  std::vector<size_t> hit_index;
  size_t traced = 0, found = 0;
  // Misses are replaced by rays through other pixels: each round traces
  // enough fresh primary rays for the hit rate seen so far (bounded rounds).
  for (int round = 0; round < 16 && out.size() < n; ++round) {
    const size_t need = n - out.size();
    const double rate = traced ? std::max(double(found) / double(traced), 0.01) : 0.5;
    const size_t want =
        std::min<size_t>(size_t(double(need) * 1.25 / rate) + 1024, size_t(1) << 26);
    const std::vector<Ray> rays = primary_rays(scene, want, rng);
    hits.resize(rays.size());
    backend->intersect(rays, hits);
    hit_index.clear();
    for (size_t i = 0; i < rays.size(); ++i) {
      const Hit& h = hits[i];
      if (!h.hit() || h.geom_id >= scene.meshes.size()) continue;
      const TriangleMesh& m = scene.meshes[h.geom_id];
      if (h.prim_id < m.triangles.size() && m.triangle_valid(h.prim_id)) hit_index.push_back(i);
    }
    traced += rays.size();
    found += hit_index.size();
    // Take hits evenly over the image (scanline order) when there are more
    // than needed, so the set covers the whole view, not its top rows.
    const size_t take = std::min(need, hit_index.size());
    for (size_t k = 0; k < take; ++k) {
      const size_t i = hit_index[size_t(double(k) * double(hit_index.size()) / double(take))];
      const Hit& h = hits[i];
      const TriangleMesh& m = scene.meshes[h.geom_id];
      const Vec3u& t = m.triangles[h.prim_id];
      const Vec3d a(m.positions[t[0]]), b(m.positions[t[1]]), c(m.positions[t[2]]);
      const double u = h.u, v = h.v;
      const Vec3f p(a * (1.0 - u - v) + b * u + c * v);
      Vec3f nrm = Vec3f(normalize(cross(b - a, c - a)));
      if (dot(nrm, rays[i].dir) > 0.0f) nrm = -nrm;
      out.push_back({p, nrm, rays[i].dir});
    }
  }
  if (out.size() < n)
    throw OptionError("kind", std::string(to_string(kind)) + ": only " +
                                  std::to_string(out.size()) + " of " + std::to_string(n) +
                                  " primary rays hit the scene (camera misses it?)");
  return out;
}

std::vector<Ray> shadow_rays(const Scene& scene, size_t n, Rng& rng, const Intersector* backend) {
  if (scene.lights.empty()) throw OptionError("kind", "shadow rays need a light in the scene");
  const Light& light = scene.lights.front();
  const std::vector<SurfaceHit> hits = primary_hits(scene, n, rng, backend, RayKind::kShadow);
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    Ray& r = rays[i];
    r.org = offset_ray(hits[i].p, hits[i].n);
    r.tnear = 0.0f;
    if (light.type == LightType::kPoint) {
      // Unnormalised direction: the light sits at t = 1; stop just short of it.
      r.dir = light.position - r.org;
      r.tfar = 1.0f - 1e-4f;
    } else {
      r.dir = normalize(-light.direction);
      r.tfar = kInf;
    }
  }
  return rays;
}

std::vector<Ray> reflection_rays(const Scene& scene, size_t n, Rng& rng,
                                 const Intersector* backend) {
  const std::vector<SurfaceHit> hits = primary_hits(scene, n, rng, backend, RayKind::kReflection);
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    const SurfaceHit& h = hits[i];
    const Vec3f d = normalize(h.dir);
    rays[i].org = offset_ray(h.p, h.n);
    rays[i].dir = d - h.n * (2.0f * dot(d, h.n));
  }
  return rays;
}

std::vector<Ray> random_rays(const Scene& scene, size_t n, Rng& rng) {
  const AABB box = scene_box(scene);
  const Vec3f c = box.center(), half = box.diagonal() * 0.55f;  // 10% larger box
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    r.org =
        c + Vec3f(half.x * (2.0f * rng.uniform() - 1.0f), half.y * (2.0f * rng.uniform() - 1.0f),
                  half.z * (2.0f * rng.uniform() - 1.0f));
    r.dir = uniform_sphere(rng);
  }
  return rays;
}

std::vector<Ray> probe_rays(const Scene& scene, size_t n, Rng& rng, RayKind kind) {
  std::vector<uint32_t> closed;
  for (uint32_t i = 0; i < scene.meshes.size(); ++i)
    if (mesh_closed(scene.meshes[i])) closed.push_back(i);
  if (closed.empty())
    throw OptionError("kind", std::string(to_string(kind)) +
                                  " rays need a closed mesh (every edge shared by two triangles)");
  std::vector<Vec3f> centroids(scene.meshes.size());
  for (uint32_t m : closed) centroids[m] = mesh_centroid(scene.meshes[m]);
  const TrianglePicker picker(scene, closed);
  std::vector<Ray> rays;
  rays.reserve(n);
  size_t attempts = 0;
  while (rays.size() < n) {
    if (++attempts > 100 * n + 1000)
      throw OptionError("kind", std::string(to_string(kind)) + ": every target is the centroid");
    const auto [mesh, tri] = picker.pick(rng, "probe");
    const TriangleMesh& m = scene.meshes[mesh];
    const int k = int(rng.below(3));
    const Vec3f a = m.positions[m.triangles[tri][k]];
    const Vec3f target =
        kind == RayKind::kVertexProbe ? a : (a + m.positions[m.triangles[tri][(k + 1) % 3]]) * 0.5f;
    Ray r;
    r.org = centroids[mesh];
    r.dir = target - r.org;  // unnormalised: the target sits at t = 1
    if (r.dir == Vec3f(0.0f)) continue;
    rays.push_back(r);
  }
  return rays;
}

std::vector<Ray> grazing_rays(const Scene& scene, size_t n, Rng& rng) {
  const TrianglePicker picker(scene, all_meshes(scene));
  require_triangles(picker, RayKind::kGrazing);
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
std::vector<Ray> axis_rays(const Scene& scene, size_t n, Rng& rng) {
  const TrianglePicker picker(scene, all_meshes(scene));
  require_triangles(picker, RayKind::kAxis);
  const AABB box = scene_box(scene);
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
std::vector<Ray> nan_rays(const Scene& scene, size_t n, Rng& rng) {
  const AABB box = scene_box(scene);
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

}  // namespace

std::string_view to_string(RayKind kind) {
  for (const KindName& k : kKinds)
    if (k.kind == kind) return k.name;
  return "?";
}

RayKind parse_ray_kind(std::string_view name) {
  for (const KindName& k : kKinds)
    if (name == k.name) return k.kind;
  std::string list;
  for (const KindName& k : kKinds) list += (list.empty() ? "" : ", ") + std::string(k.name);
  throw OptionError("kind", "unknown ray kind '" + std::string(name) + "' (expected " + list + ")");
}

std::vector<std::string> ray_kind_names() {
  std::vector<std::string> v;
  for (const KindName& k : kKinds) v.emplace_back(k.name);
  return v;
}

std::vector<Ray> make_rays(const Scene& scene, RayKind kind, size_t n, uint64_t seed,
                           const Intersector* backend) {
  if (n == 0) return {};
  // Different kinds with the same seed get unrelated streams.
  Rng rng(seed * kSplitMixGamma + uint64_t(kind) + 1);
  switch (kind) {
    case RayKind::kPrimary:
      return primary_rays(scene, n, rng);
    case RayKind::kShadow:
      return shadow_rays(scene, n, rng, backend);
    case RayKind::kReflection:
      return reflection_rays(scene, n, rng, backend);
    case RayKind::kRandom:
      return random_rays(scene, n, rng);
    case RayKind::kVertexProbe:
    case RayKind::kEdgeProbe:
      return probe_rays(scene, n, rng, kind);
    case RayKind::kGrazing:
      return grazing_rays(scene, n, rng);
    case RayKind::kAxis:
      return axis_rays(scene, n, rng);
    case RayKind::kNan:
      return nan_rays(scene, n, rng);
  }
  throw OptionError("kind", "unknown ray kind");
}

}  // namespace hprt
