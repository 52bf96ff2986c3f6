// Progress bar: "label [#####.....]  52%  ETA 3.1 s" redrawn in place with \r.
#include "render/progress.h"

#include <unistd.h>

#include <cstdio>

namespace hprt {
namespace {
constexpr double kShowAfterS = 1.0;  // never shown for renders faster than this
constexpr double kRedrawEveryS = 0.1;
constexpr int kBarWidth = 30;
}  // namespace

Progress::Progress(std::string label, size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      tty_(enabled && ::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

void Progress::advance(size_t n) {
  const size_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
  if (!tty_) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (elapsed < kShowAfterS) return;
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_ || elapsed - last_draw_s_ < kRedrawEveryS) return;
  draw(done, elapsed);
}

void Progress::finish() {
  std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (!drawn_) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  draw(done_.load(), elapsed);
  std::fputc('\n', stderr);
}

void Progress::draw(size_t done, double elapsed_s) {
  last_draw_s_ = elapsed_s;
  drawn_ = true;
  const double frac = total_ ? double(done) / double(total_) : 1.0;
  const int filled = int(frac * kBarWidth + 0.5);
  char bar[kBarWidth + 1];
  for (int i = 0; i < kBarWidth; ++i) bar[i] = i < filled ? '#' : '.';
  bar[kBarWidth] = '\0';
  if (done < total_ && frac > 0.0) {
    const double eta = elapsed_s * (1.0 - frac) / frac;
    std::fprintf(stderr, "\r%s [%s] %3d%%  ETA %.1f s   ", label_.c_str(), bar, int(frac * 100),
                 eta);
  } else {
    std::fprintf(stderr, "\r%s [%s] %3d%%  %.1f s       ", label_.c_str(), bar, int(frac * 100),
                 elapsed_s);
  }
  std::fflush(stderr);
}

}  // namespace hprt
