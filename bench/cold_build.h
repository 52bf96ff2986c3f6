// Cold builds: what a user of `hprt trace` or `hprt render` pays for the
// first build of a fresh process (fresh memory faulted in, worker threads
// started), beside the warm in-process repetitions of the build table. Each
// sample runs `hprt trace SCENE --rays (one ray) --backend B --threads T
// --json` as a child process and reads its build_ms.
#pragma once

#include <filesystem>
#include <string>

#include "bench/bench_inputs.h"

namespace hprt::bench {

class ColdBuilds {
 public:
  // A scratch directory with the one-ray file, and a PLY of the input where
  // it is not a file already (a generated mesh). Throws on I/O errors.
  explicit ColdBuilds(const BenchInput& in);
  ~ColdBuilds();
  ColdBuilds(const ColdBuilds&) = delete;
  ColdBuilds& operator=(const ColdBuilds&) = delete;

  // One fresh process's build_ms with `backend` (bvh, embree) at `threads`.
  // Throws std::runtime_error when the child fails.
  double build_ms(const std::string& backend, int threads) const;

 private:
  std::filesystem::path dir_, scene_, rays_;
};

}  // namespace hprt::bench
