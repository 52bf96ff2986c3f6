// Fail-fast check for an output path before any expensive work: its directory
// must exist (the atomic write re-checks at the end).
#pragma once

#include <filesystem>
#include <string>

#include "core/error.h"

namespace hprt::cli {

inline void check_output_directory(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
    throw InputError(path, "output directory '" + parent.string() + "' does not exist");
}

}  // namespace hprt::cli
