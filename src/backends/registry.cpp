// Backend registry: the only place that knows every backend by name.
#include "backends/bvh_backend.h"
#include "backends/embree_backend.h"
#include "backends/intersector.h"
#include "core/error.h"

namespace hprt {

std::unique_ptr<Intersector> make_intersector(std::string_view backend,
                                              const BackendOptions& options) {
  if (backend == "bvh") return make_bvh_intersector(options);
  if (backend == "embree") return make_embree_intersector(options);
  throw OptionError("backend",
                    "unknown backend '" + std::string(backend) + "' (expected bvh or embree)");
}

}  // namespace hprt
