// Intel Embree 3 as the reference backend behind the Intersector interface.
#pragma once

#include <memory>

#include "backends/intersector.h"

namespace hprt {

std::unique_ptr<Intersector> make_embree_intersector(const BackendOptions& options);

}  // namespace hprt
