// Backend registry: the only place that knows every backend by name.
#include "backends/backend_spec.h"
#include "backends/bvh_backend.h"
#include "backends/embree_backend.h"
#include "backends/intersector.h"
#include "backends/plugin_backend.h"
#include "core/error.h"

namespace hprt {

std::unique_ptr<Intersector> make_intersector(std::string_view backend,
                                              const BackendOptions& options) {
  const BackendSpec spec = parse_backend_spec(backend);
  switch (spec.kind) {
    case BackendSpec::Kind::kEmbree:
      return make_embree_intersector(options);
    case BackendSpec::Kind::kPlugin:
      return make_plugin_intersector(spec, options);
    case BackendSpec::Kind::kBvh:
      break;
  }
  return make_bvh_intersector(options);
}

// Backends without the queries say so (the plugin ABI has no such call).
void Intersector::count(const RayInput&, std::span<uint32_t>) const {
  throw OptionError("backend", info().name + " does not answer count queries");
}
void Intersector::intersect_all(const RayInput&, uint32_t, HitLists&) const {
  throw OptionError("backend", info().name + " does not answer all-hits queries");
}
void Intersector::locate(std::span<const Vec3f>, std::span<PointLocation>) const {
  throw OptionError("backend", info().name + " does not answer inside queries");
}
void Intersector::closest(std::span<const Vec3f>, float, std::span<ClosestPoint>) const {
  throw OptionError("backend", info().name + " does not answer closest-point queries");
}

}  // namespace hprt
