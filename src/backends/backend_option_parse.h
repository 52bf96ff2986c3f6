// Backend options by name, for front ends that take them as text (the public
// API's Options, the Python keyword arguments): the command line's option
// names without dashes and with '_' for '-', and the same values and checks.
#pragma once

#include <string_view>

#include "backends/intersector.h"

namespace hprt {

// Sets one option of `o`. Throws OptionError(key, problem) for an unknown key
// or a bad value.
void set_backend_option(BackendOptions& o, std::string_view key, std::string_view value);

}  // namespace hprt
