// TEMPORARY placeholder until the BVH backend lands (issue 4); must be replaced.
#include "backends/bvh_backend.h"

#include "core/error.h"

namespace hprt {

std::unique_ptr<Intersector> make_bvh_intersector(const BackendOptions&) {
  throw InputError("--backend", "bvh backend not built yet");
}

}  // namespace hprt
