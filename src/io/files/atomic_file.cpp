#include "io/files/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>

#include "core/error.h"

namespace hprt {
namespace {

// Fixed-size table of live temporary paths, readable from a signal handler
// (no allocation, no locks there): each slot is a pointer published atomically.
constexpr int kMaxLive = 64;
std::array<std::atomic<const char*>, kMaxLive> g_live{};

void register_temp(const char* p) {
  for (auto& slot : g_live) {
    const char* expected = nullptr;
    if (slot.compare_exchange_strong(expected, p)) return;
  }
}
void unregister_temp(const char* p) {
  for (auto& slot : g_live) {
    const char* expected = p;
    if (slot.compare_exchange_strong(expected, nullptr)) return;
  }
}

extern "C" void cleanup_on_signal(int sig) {
  for (auto& slot : g_live) {
    const char* p = slot.load();
    if (p) ::unlink(p);
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  temp_ = path_ + ".tmp-" + std::to_string(::getpid()) + "-" +
          std::to_string(reinterpret_cast<uintptr_t>(this) & 0xffffff);
  int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(path_, std::string("cannot write: ") + std::strerror(errno));
  ::close(fd);
  register_temp(temp_.c_str());
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    unregister_temp(temp_.c_str());
    ::unlink(temp_.c_str());
  }
}

void AtomicFile::commit() {
  if (committed_) return;
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    throw InputError(path_,
                     std::string("cannot rename output into place: ") + std::strerror(errno));
  unregister_temp(temp_.c_str());
  committed_ = true;
}

void write_file_atomic(const std::string& path, const void* data, size_t size) {
  AtomicFile out(path);
  std::FILE* f = std::fopen(out.temp_path().c_str(), "wb");
  if (!f) throw InputError(path, std::string("cannot write: ") + std::strerror(errno));
  const size_t written = size ? std::fwrite(data, 1, size, f) : 0;
  const bool ok = written == size && std::fflush(f) == 0;
  const bool closed = std::fclose(f) == 0;  // the last buffered bytes may fail here
  if (!ok || !closed) throw InputError(path, "write failed (disk full?)");
  out.commit();
}

void install_output_cleanup_handlers() {
  std::signal(SIGINT, cleanup_on_signal);
  std::signal(SIGTERM, cleanup_on_signal);
}

}  // namespace hprt
