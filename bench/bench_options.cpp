// Checks of the shared bench options.
#include "bench/bench_options.h"

#include <filesystem>
#include <system_error>

#include "core/error.h"
#include "core/parallel.h"

namespace hprt::bench {

void check_bench_options(const BenchOptions& o) {
  if (o.repeat && (*o.repeat < 1 || *o.repeat > kMaxRepeat))
    throw OptionError("repeat", "must be in [1, " + std::to_string(kMaxRepeat) + "] (got " +
                                    std::to_string(*o.repeat) + ")");
  if (o.threads < 0 || o.threads > kMaxThreads)
    throw OptionError("threads", "must be 0 (all) or a count up to " + std::to_string(kMaxThreads) +
                                     " (got " + std::to_string(o.threads) + ")");
  if (!o.out_dir.empty()) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (fs::exists(o.out_dir, ec)) {
      if (!fs::is_directory(o.out_dir, ec))
        throw InputError(o.out_dir, "--out must be a directory");
    } else if (!fs::create_directories(o.out_dir, ec) || ec) {
      throw InputError(o.out_dir, "cannot create the --out directory: " + ec.message());
    }
  }
}

int repetitions(const BenchOptions& o, int full_default, int quick_default) {
  if (o.repeat) return *o.repeat;
  return o.quick ? quick_default : full_default;
}

std::vector<int> thread_counts(const BenchOptions& o) {
  const int all = resolve_threads(o.threads);
  if (all <= 1) return {1};
  return {1, all};
}

}  // namespace hprt::bench
