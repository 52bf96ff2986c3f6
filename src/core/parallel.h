// `--threads N` means N: all of hprt's parallel work runs inside a
// tbb::task_arena of that size (0 = every hardware thread).
#pragma once

#include <tbb/task_arena.h>

#include <utility>

namespace hprt {

// The most threads any option asks for (--threads, threads=, nthreads): a
// task arena is sized by it, and oneTBB fails on absurd sizes.
inline constexpr int kMaxThreads = 4096;

inline int resolve_threads(int requested) {
  return requested > 0 ? requested : tbb::this_task_arena::max_concurrency();
}

template <typename F>
decltype(auto) run_with_threads(int threads, F&& f) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  return arena.execute(std::forward<F>(f));
}

}  // namespace hprt
