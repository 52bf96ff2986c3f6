// Backend registry: the only place that knows every backend by name.
#include "backends/backend_spec.h"
#include "backends/bvh_backend.h"
#include "backends/embree_backend.h"
#include "backends/intersector.h"
#include "backends/plugin_backend.h"

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

}  // namespace hprt
