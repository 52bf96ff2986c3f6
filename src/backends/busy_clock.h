// Wall time during which at least one query of a backend was running, and
// the rays (or points) those queries took: calls from several threads at
// once (a renderer's tiles) count once, so the time compares with a build's
// wall time. A mutex per batch call: the batches are hundreds of rays and
// more.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>

#include "core/stopwatch.h"

namespace hprt {

class BusyClock {
 public:
  // Times one call of `items` rays or points while it lives; does nothing
  // for a null clock.
  class Scope {
   public:
    Scope(BusyClock* clock, size_t items) : clock_(clock) {
      if (clock_) clock_->start(items);
    }
    ~Scope() {
      if (clock_) clock_->stop();
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    BusyClock* clock_;
  };

  struct Busy {
    double ms = 0.0;
    uint64_t items = 0;
  };
  // Since the last take (calls still running count up to now).
  Busy take() {
    std::lock_guard lock(mutex_);
    Busy b{ms_, items_};
    if (running_ > 0) {
      const auto now = Clock::now();
      b.ms += std::chrono::duration<double, std::milli>(now - since_).count();
      since_ = now;
    }
    ms_ = 0.0;
    items_ = 0;
    return b;
  }

 private:
  void start(size_t items) {
    std::lock_guard lock(mutex_);
    items_ += items;
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
  uint64_t items_ = 0;
};

}  // namespace hprt
