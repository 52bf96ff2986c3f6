// The point-set catalogue (see point_sets.h).
#include "validators/point_sets.h"

#include <array>
#include <cmath>

#include "core/error.h"
#include "core/splitmix64.h"

namespace hprt {
namespace {

struct KindName {
  PointKind kind;
  const char* name;
};
constexpr std::array<KindName, 3> kKinds{
    {{PointKind::kRandom, "random"}, {PointKind::kNear, "near"}, {PointKind::kHard, "hard"}}};

struct TriangleRef {
  uint32_t mesh, prim;
};

}  // namespace

std::string_view to_string(PointKind kind) {
  for (const KindName& k : kKinds)
    if (k.kind == kind) return k.name;
  return "?";
}

PointKind parse_point_kind(std::string_view name) {
  for (const KindName& k : kKinds)
    if (name == k.name) return k.kind;
  std::string list;
  for (const KindName& k : kKinds) list += (list.empty() ? "" : ", ") + std::string(k.name);
  throw OptionError("kind",
                    "unknown point kind '" + std::string(name) + "' (expected " + list + ")");
}

std::vector<std::string> point_kind_names() {
  std::vector<std::string> v;
  for (const KindName& k : kKinds) v.emplace_back(k.name);
  return v;
}

std::vector<Vec3f> make_points(const Scene& scene, PointKind kind, size_t n, uint64_t seed,
                               const std::string& scene_name) {
  std::vector<TriangleRef> valid;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m)
    for (uint32_t i = 0; i < scene.meshes[m].triangle_count(); ++i)
      if (scene.meshes[m].triangle_valid(i)) valid.push_back({m, i});
  if (valid.empty()) throw InputError(scene_name, "no valid triangle to place points around");
  AABB box;
  for (const TriangleRef& r : valid) {
    const TriangleMesh& m = scene.meshes[r.mesh];
    for (int k = 0; k < 3; ++k) box.extend(m.positions[m.triangles[r.prim][k]]);
  }
  // Different kinds with the same seed get unrelated streams.
  SplitMix64 rng(seed * kSplitMixGamma + uint64_t(kind) + 101);
  const auto in_box = [&](int a) {
    const double lo = box.min[a], hi = box.max[a];
    return float(lo + (hi - lo) * (1.2 * double(rng.uniform()) - 0.1));
  };
  const auto random_point = [&] { return Vec3f{in_box(0), in_box(1), in_box(2)}; };
  const auto vertex = [&](const TriangleRef& r, int k) {
    const TriangleMesh& m = scene.meshes[r.mesh];
    return m.positions[m.triangles[r.prim][k]];
  };
  std::vector<Vec3f> out;
  out.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const TriangleRef& t = valid[rng.below(valid.size())];
    if (kind == PointKind::kRandom) {
      out.push_back(random_point());
      continue;
    }
    if (kind == PointKind::kNear) {
      double u = rng.uniform(), v = rng.uniform();
      if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
      const Vec3f a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
      Vec3f p;
      for (int k = 0; k < 3; ++k)
        p[k] = float(double(a[k]) + u * (double(b[k]) - a[k]) + v * (double(c[k]) - a[k]));
      out.push_back(p);
      continue;
    }
    const Vec3f v = vertex(t, int(rng.below(3)));
    Vec3f p = random_point();
    switch (i % 5) {
      case 0:
        break;
      case 1: {
        const int a = int(rng.below(3));
        p[a] = v[a];
        break;
      }
      case 2:
        p = v;
        break;
      case 3: {
        p = v;
        const int a = int(rng.below(3));
        p[a] = std::nextafter(p[a], rng.coin() ? HUGE_VALF : -HUGE_VALF);
        break;
      }
      default:
        p[0] = v[0];
        p[1] = v[1];
        break;
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace hprt
