// The render target: linear float RGB, row 0 at the top, row-major.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/vec.h"

namespace hprt {

// The widest and tallest image any render makes (--width, --height).
inline constexpr int kMaxImageSide = 65536;

class Framebuffer {
 public:
  Framebuffer() = default;
  Framebuffer(int width, int height)
      : width_(width), height_(height), pixels_(size_t(width) * size_t(height), Vec3f(0.0f)) {}

  int width() const { return width_; }
  int height() const { return height_; }
  Vec3f& at(int x, int y) { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
  const Vec3f& at(int x, int y) const { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
  std::span<const Vec3f> pixels() const { return pixels_; }
  std::span<Vec3f> pixels() { return pixels_; }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<Vec3f> pixels_;
};

}  // namespace hprt
