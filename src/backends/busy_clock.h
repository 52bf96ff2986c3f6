// Wall time during which at least one query of a backend was running:
// calls from several threads at once (a renderer's tiles) count once, so
// the time compares with a build's wall time. Lock-free: a renderer makes
// thousands of small batch calls a frame from every thread, and a lock
// taken at each call's start and end would make them wait on each other.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

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
    uint64_t s = state_.load();
    while (running(s) > 0) {
      const uint64_t t = now_us();
      if (state_.compare_exchange_weak(s, pack(running(s), t))) {
        busy_us_.fetch_add(t - since(s));
        break;
      }
    }
    return double(busy_us_.exchange(0)) / 1000.0;
  }

 private:
  // state_: the calls running (top 16 bits) and, while any runs, when the
  // busy stretch began (the low 48 bits: us since the clock was made, 8.9
  // years), changed together by compare-exchange.
  static constexpr int kSinceBits = 48;
  static constexpr uint64_t kSinceMask = (uint64_t{1} << kSinceBits) - 1;
  static uint64_t running(uint64_t s) { return s >> kSinceBits; }
  static uint64_t since(uint64_t s) { return s & kSinceMask; }
  static uint64_t pack(uint64_t running, uint64_t since) {
    return running << kSinceBits | (since & kSinceMask);
  }
  uint64_t now_us() const {
    return uint64_t(
        std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - epoch_).count());
  }

  void start() {
    uint64_t s = state_.load();
    for (;;) {
      const uint64_t next = running(s) == 0 ? pack(1, now_us()) : pack(running(s) + 1, since(s));
      if (state_.compare_exchange_weak(s, next)) return;
    }
  }
  void stop() {
    uint64_t s = state_.load();
    for (;;) {
      if (running(s) == 1) {
        const uint64_t t = now_us();
        if (state_.compare_exchange_weak(s, 0)) {
          busy_us_.fetch_add(t - since(s));
          return;
        }
      } else if (state_.compare_exchange_weak(s, pack(running(s) - 1, since(s)))) {
        return;
      }
    }
  }

  const Clock::time_point epoch_ = Clock::now();
  std::atomic<uint64_t> state_{0};
  std::atomic<uint64_t> busy_us_{0};
};

}  // namespace hprt
