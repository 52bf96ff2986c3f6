// The ray-set catalogue (see ray_sets.h): the workload kinds come from
// src/workload, the hard ones from hard_rays.h.
#include "validators/ray_sets.h"

#include <array>

#include "core/error.h"
#include "core/splitmix64.h"
#include "validators/hard_rays.h"
#include "workload/workload_rays.h"

namespace hprt {
namespace {

struct KindName {
  RayKind kind;
  const char* name;
};
constexpr std::array<KindName, 10> kKinds{{{RayKind::kPrimary, "primary"},
                                           {RayKind::kShadow, "shadow"},
                                           {RayKind::kReflection, "reflection"},
                                           {RayKind::kDiffuse, "diffuse"},
                                           {RayKind::kRandom, "random"},
                                           {RayKind::kVertexProbe, "vertex-probe"},
                                           {RayKind::kEdgeProbe, "edge-probe"},
                                           {RayKind::kGrazing, "grazing"},
                                           {RayKind::kAxis, "axis"},
                                           {RayKind::kNan, "nan"}}};

}  // namespace

std::string_view to_string(RayKind kind) {
  for (const KindName& k : kKinds)
    if (k.kind == kind) return k.name;
  return "?";
}

bool ray_kind_needs_backend(RayKind kind) {
  return kind == RayKind::kShadow || kind == RayKind::kReflection || kind == RayKind::kDiffuse;
}

RayKind parse_ray_kind(std::string_view name) {
  for (const KindName& k : kKinds)
    if (name == k.name) return k.kind;
  std::string list;
  for (const KindName& k : kKinds) list += (list.empty() ? "" : ", ") + std::string(k.name);
  throw OptionError("kind", "unknown ray kind '" + std::string(name) + "' (expected " + list + ")");
}

void check_ray_count(const std::string& key, size_t n) {
  if (n > kMaxRaySetSize)
    throw OptionError(key, "too many rays: " + std::to_string(n) + " (at most " +
                               std::to_string(kMaxRaySetSize) + ")");
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
  SplitMix64 rng(seed * kSplitMixGamma + uint64_t(kind) + 1);
  switch (kind) {
    case RayKind::kPrimary:
      return primary_rays(scene, n, rng);
    case RayKind::kShadow:
      return shadow_rays(scene, n, rng, backend);
    case RayKind::kReflection:
      return reflection_rays(scene, n, rng, backend);
    case RayKind::kDiffuse:
      return diffuse_rays(scene, n, rng, backend);
    case RayKind::kRandom:
      return random_rays(scene, n, rng);
    case RayKind::kVertexProbe:
    case RayKind::kEdgeProbe:
      return probe_rays(scene, n, rng, kind == RayKind::kVertexProbe);
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
