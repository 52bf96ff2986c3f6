// What the mesh reader and writer tests share: a scratch directory that is
// removed with its contents, and Debian's assimp-testmodels (real files in
// many dialects; scripts/setup.sh installs them, tests skip without them).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace hprt::test {

inline const std::string kAssimpModels = "/usr/share/assimp/models/";

#define HPRT_SKIP_IF_MISSING(p)    \
  if (!std::filesystem::exists(p)) \
  GTEST_SKIP() << (p) << " missing: install assimp-testmodels (scripts/setup.sh)"

// <tmp>/<name>_<pid>: CTest runs each test in its own process, so tests
// running at once never share one.
struct TempDir {
  std::filesystem::path dir;
  explicit TempDir(const std::string& name)
      : dir(std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir);
  }
  ~TempDir() { std::filesystem::remove_all(dir); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string path(const std::string& name) const { return (dir / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return path(name);
  }
};

}  // namespace hprt::test
