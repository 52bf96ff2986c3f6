// Wall-clock milliseconds on the steady clock, as every timing hprt reports.
#pragma once

#include <chrono>

namespace hprt {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace hprt
