// Numbered file names: a printf-style pattern with exactly one integer
// conversion (%d, %5d, %04d; "%%" is a literal %), formatted without printf so
// a pattern from a user or a scene file can never read past its arguments.
#pragma once

#include <string>

namespace hprt {

// Whether `pattern` holds exactly one valid %d-style conversion. Throws
// InputError(what, problem) for a malformed one (a % not followed by
// [0][width]d or %, or more than one conversion).
bool has_frame_number(const std::string& pattern, const std::string& what);

// `pattern` with its conversion replaced by `number` (printf semantics for
// %d, %Nd and %0Nd). A pattern without a conversion is returned unchanged
// (with %% unescaped).
std::string format_frame_path(const std::string& pattern, long long number);

}  // namespace hprt
