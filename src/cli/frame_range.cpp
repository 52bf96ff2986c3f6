// Parsing and range checks for `--frames A:B`.
#include "cli/frame_range.h"

#include <charconv>

#include "core/error.h"

namespace hprt::cli {
namespace {

bool parse_int(const std::string& s, int& v) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  return std::from_chars(s.data(), s.data() + s.size(), v).ec == std::errc();
}

}  // namespace

FrameRange parse_frame_range(const std::string& text, int frames) {
  const size_t colon = text.find(':');
  FrameRange r;
  if (colon == std::string::npos || !parse_int(text.substr(0, colon), r.first) ||
      !parse_int(text.substr(colon + 1), r.end))
    throw InputError("--frames", "expected A:B (frames A to B-1, e.g. 0:24), got '" + text + "'");
  if (r.first >= r.end)
    throw InputError("--frames", "empty range '" + text + "': A must be less than B");
  if (r.end > frames)
    throw InputError("--frames", "'" + text + "' goes past the animation's " +
                                     std::to_string(frames) + " frame" + (frames == 1 ? "" : "s") +
                                     " (0:" + std::to_string(frames) + ")");
  return r;
}

}  // namespace hprt::cli
