// Numbered file names (see frame_pattern.h): a small parser for one
// %[0][width]d conversion, so no user text ever reaches printf.
#include "core/frame_pattern.h"

#include <cstdlib>
#include <string>

#include "core/error.h"

namespace hprt {
namespace {

constexpr int kMaxWidth = 32;

struct Conversion {
  size_t begin = std::string::npos;  // index of '%'
  size_t end = 0;                    // one past 'd'
  bool zero_pad = false;
  int width = 0;
};

// Finds the one conversion; throws for malformed or repeated ones.
Conversion parse(const std::string& pattern, const std::string& what) {
  Conversion conv;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      ++i;
      continue;
    }
    size_t j = i + 1;
    Conversion c;
    c.begin = i;
    if (j < pattern.size() && pattern[j] == '0') {
      c.zero_pad = true;
      ++j;
    }
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9') {
      c.width = c.width * 10 + (pattern[j] - '0');
      if (c.width > kMaxWidth)
        throw InputError(what,
                         "field width in '" + pattern + "' is above " + std::to_string(kMaxWidth));
      ++j;
    }
    if (j >= pattern.size() || pattern[j] != 'd')
      throw InputError(what,
                       "'" + pattern + "': a % must start %d, %4d or %04d (or be written %%)");
    if (conv.begin != std::string::npos)
      throw InputError(what, "'" + pattern + "' has more than one %d conversion");
    c.end = j + 1;
    conv = c;
    i = j;
  }
  return conv;
}

std::string unescape(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    out += s[i];
    if (s[i] == '%' && i + 1 < s.size() && s[i + 1] == '%') ++i;
  }
  return out;
}

}  // namespace

bool has_frame_number(const std::string& pattern, const std::string& what) {
  return parse(pattern, what).begin != std::string::npos;
}

std::string format_frame_path(const std::string& pattern, long long number) {
  const Conversion c = parse(pattern, pattern);
  if (c.begin == std::string::npos) return unescape(pattern);
  std::string digits =
      std::to_string(number < 0 ? -(unsigned long long)number : (unsigned long long)number);
  const std::string sign = number < 0 ? "-" : "";
  std::string field;
  const size_t width = size_t(c.width);
  if (c.zero_pad && sign.size() + digits.size() < width)
    field = sign + std::string(width - sign.size() - digits.size(), '0') + digits;
  else
    field = sign + digits;
  if (field.size() < width) field = std::string(width - field.size(), ' ') + field;
  return unescape(pattern.substr(0, c.begin)) + field + unescape(pattern.substr(c.end));
}

}  // namespace hprt
