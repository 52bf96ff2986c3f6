// Embree device set-up and error/memory bookkeeping (see embree_device.h).
#include "backends/embree_device.h"

#include <stdexcept>

namespace hprt {
namespace {

const char* error_name(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "no error";
    case RTC_ERROR_UNKNOWN:
      return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
  }
  return "unrecognised error";
}

}  // namespace

EmbreeDevice::EmbreeDevice(int threads) {
  const std::string config = "threads=" + std::to_string(threads) + ",verbose=0";
  device_ = rtcNewDevice(config.c_str());
  if (!device_)
    throw std::runtime_error(std::string("embree: rtcNewDevice failed: ") +
                             error_name(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(device_, &EmbreeDevice::on_error, this);
  rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeDevice::on_memory, this);
}

EmbreeDevice::~EmbreeDevice() {
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeDevice::on_error(void* self, RTCError code, const char* message) {
  auto* d = static_cast<EmbreeDevice*>(self);
  std::lock_guard lock(d->mutex_);
  d->last_error_ = std::string(error_name(code)) + (message ? std::string(": ") + message : "");
}

bool EmbreeDevice::on_memory(void* self, ssize_t bytes, bool /*post*/) {
  // Called with positive sizes before allocations and negative ones after
  // frees; never refuses an allocation.
  auto* d = static_cast<EmbreeDevice*>(self);
  const long long now = d->current_.fetch_add(bytes) + bytes;
  long long peak = d->peak_.load();
  while (now > peak && !d->peak_.compare_exchange_weak(peak, now)) {
  }
  return true;
}

void EmbreeDevice::check(const char* what) const {
  const RTCError code = rtcGetDeviceError(device_);
  if (code == RTC_ERROR_NONE) return;
  std::string message;
  {
    std::lock_guard lock(mutex_);
    message = last_error_.empty() ? error_name(code) : last_error_;
    last_error_.clear();
  }
  throw std::runtime_error(std::string("embree: ") + what + ": " + message);
}

}  // namespace hprt
