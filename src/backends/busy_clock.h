// Wall time during which at least one query of a backend was running:
// calls from several threads at once (a renderer's tiles) count once, so
// the time compares with a build's wall time. A mutex per batch call: the batches are hundreds of
// rays and more.
#pragma once

#include <mutex>

#include "core/stopwatch.h"

namespace hprt {

class BusyClock {
 public:
  // Times one call while it lives; does nothing for a null clock.
  class Scope {
   public:
    explicit Scope(BusyClock* clock) : clock_(clock) {
      if (clock_) clock_->start();
    }
    ~Scope() {
      if (clock_) clock_->stop();
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    BusyClock* clock_;
  };

  // The busy ms since the last take (calls still running count up to now).
  double take_ms() {
    std::lock_guard lock(mutex_);
    double ms = ms_;
    if (running_ > 0) {
      const auto now = Clock::now();
      ms += std::chrono::duration<double, std::milli>(now - since_).count();
      since_ = now;
    }
    ms_ = 0.0;
    return ms;
  }

 private:
  void start() {
    std::lock_guard lock(mutex_);
    if (running_++ == 0) since_ = Clock::now();
  }
  void stop() {
    std::lock_guard lock(mutex_);
    if (--running_ == 0) ms_ += ms_since(since_);
  }

  std::mutex mutex_;
  int running_ = 0;
  Clock::time_point since_;
  double ms_ = 0.0;
};

}  // namespace hprt
