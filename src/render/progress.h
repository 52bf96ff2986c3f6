// A progress bar with ETA on stderr, shown only when stderr is a terminal and
// the work has taken more than a second; silent otherwise (pipes, logs, tests).
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace hprt {

class Progress {
 public:
  // `enabled = false` forces silence (e.g. --json runs that want clean output).
  Progress(std::string label, size_t total, bool enabled = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Thread-safe; redraws at most ten times a second.
  void advance(size_t n = 1);
  // Draws the final state and ends the line (only if anything was drawn).
  void finish();

 private:
  void draw(size_t done, double elapsed_s);

  std::string label_;
  size_t total_;
  bool tty_;
  std::chrono::steady_clock::time_point start_;
  std::atomic<size_t> done_{0};
  std::mutex mutex_;
  double last_draw_s_ = 0.0;
  bool drawn_ = false;
  bool finished_ = false;
};

}  // namespace hprt
