// Prints core/hit_check.h's malformed-answer warning as one stderr line of
// the command, when there is one.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "core/hit_check.h"

namespace hprt::cli {

inline void warn_malformed(const char* command, const std::string& backend_name,
                           uint64_t malformed) {
  const std::string w = malformed_warning(backend_name, malformed);
  if (!w.empty()) std::fprintf(stderr, "%s: warning: %s\n", command, w.c_str());
}

}  // namespace hprt::cli
