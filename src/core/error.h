// The one exception type for bad input. Its message reads "what: problem"
// (a path or an option name first) and the CLI prints it on one line, exit 2.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

namespace hprt {

// `text` (a file's own bytes, a JSON string, a plugin's name) safe to print
// on one line: control characters written as escapes ("\n", "\x1b").
inline std::string one_line(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      char esc[5];
      std::snprintf(esc, sizeof esc, "\\x%02x", u);
      out += esc;
    } else {
      out += c;
    }
  }
  return out;
}

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& what_it_is, const std::string& problem)
      : std::runtime_error(one_line(what_it_is + ": " + problem)) {}
  explicit InputError(const std::string& message) : std::runtime_error(one_line(message)) {}
};

// A bad value of a named option. The library names an option by its key, the
// snake_case word every front end shares (leaf_size, bins, quality, kind, ...);
// what() reads "key: problem", and each front end shows the key its own way:
// the CLI as its flag (--leaf-size), Python as the keyword argument.
class OptionError : public InputError {
 public:
  OptionError(const std::string& key, const std::string& problem)
      : InputError(key, problem), key_(key) {}
  const std::string& key() const { return key_; }
  // what() without the leading "key: ".
  const char* problem() const { return what() + key_.size() + 2; }

 private:
  std::string key_;
};

}  // namespace hprt
