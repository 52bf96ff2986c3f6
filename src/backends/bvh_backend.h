// hprt's own BVH behind the Intersector interface.
#pragma once

#include <memory>

#include "backends/intersector.h"

namespace hprt {

std::unique_ptr<Intersector> make_bvh_intersector(const BackendOptions& options);

}  // namespace hprt
