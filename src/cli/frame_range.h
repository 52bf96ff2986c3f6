// `--frames A:B` of `hprt render`: the half-open frame range [A, B).
#pragma once

#include <string>

namespace hprt::cli {

struct FrameRange {
  int first = 0;  // A
  int end = 1;    // B (exclusive)
  int count() const { return end - first; }
};

// Parses "A:B" (decimal, 0 <= A < B). Throws InputError("--frames", ...) for
// anything else; `frames` (the animation's frame count) bounds B.
FrameRange parse_frame_range(const std::string& text, int frames);

}  // namespace hprt::cli
