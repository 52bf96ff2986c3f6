// A backend loaded from a shared library through the C plugin ABI
// (include/hprt/plugin.h), behind the Intersector interface.
#pragma once

#include <memory>

#include "backends/backend_spec.h"
#include "backends/intersector.h"

namespace hprt {

// Loads spec.plugin_path and creates the plugin's backend with
// spec.plugin_options and options.threads. Throws InputError naming the file
// when it cannot be loaded, has no hprt_plugin_entry, an ABI version other
// than 1 or a NULL function, or when create() fails.
std::unique_ptr<Intersector> make_plugin_intersector(const BackendSpec& spec,
                                                     const BackendOptions& options);

}  // namespace hprt
