// Fail-fast check for an output path before any expensive work: a file name,
// not a directory, in a directory that exists (the atomic write re-checks at
// the end).
#pragma once

#include <filesystem>
#include <string>

#include "core/error.h"

namespace hprt::cli {

inline void check_output_directory(const std::string& path) {
  std::error_code ec;
  if (path.empty()) throw InputError("output path", "empty file name");
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, "is a directory: name a file to write");
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
    throw InputError(path, "output directory '" + parent.string() + "' does not exist");
}

}  // namespace hprt::cli
