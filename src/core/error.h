// The one exception type for bad input. Its message reads "what: problem"
// (a path or an option name first) and the CLI prints it on one line, exit 2.
#pragma once

#include <stdexcept>
#include <string>

namespace hprt {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& what_it_is, const std::string& problem)
      : std::runtime_error(what_it_is + ": " + problem) {}
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
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
