// Per-process temp file for fuzz targets whose reader only takes a path:
// /tmp/hprt_fuzz_<pid><ext>, removed when the fuzzer exits normally.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <string>

struct TempFile {
  explicit TempFile(const std::string& ext)
      : path("/tmp/hprt_fuzz_" + std::to_string(getpid()) + ext) {}
  ~TempFile() { std::remove(path.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  std::string path;
};
