// RAII owner of an Embree 3 device: thread count from the config string, an
// error callback that records Embree's message (check() turns it into a
// std::runtime_error) and a memory monitor counting the bytes Embree holds.
#pragma once

#include <embree3/rtcore.h>

#include <atomic>
#include <cstddef>
#include <mutex>
#include <string>

namespace hprt {

class EmbreeDevice {
 public:
  explicit EmbreeDevice(int threads);  // threads >= 1
  ~EmbreeDevice();
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;

  RTCDevice get() const { return device_; }
  // Throws std::runtime_error("embree: <what>: <message>") if the device has
  // an error pending; Embree errors are internal errors, not bad input.
  void check(const char* what) const;
  size_t current_bytes() const { return size_t(current_.load() < 0 ? 0 : current_.load()); }
  size_t peak_bytes() const { return size_t(peak_.load() < 0 ? 0 : peak_.load()); }

 private:
  static void on_error(void* self, RTCError code, const char* message);
  static bool on_memory(void* self, ssize_t bytes, bool post);

  RTCDevice device_ = nullptr;
  mutable std::mutex mutex_;
  mutable std::string last_error_;
  std::atomic<long long> current_{0};
  std::atomic<long long> peak_{0};
};

}  // namespace hprt
