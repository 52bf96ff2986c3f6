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

}  // namespace hprt
