// A problem found in one line of a text log (Vector ASC, CSV), in the same shape
// as a candump line's: a stable counter name, where, and what to do about it.
#pragma once

#include <cstddef>
#include <string>

namespace resolver {

struct TextProblem {
  std::string reason;       ///< stable snake_case counter name ("bad_hex", "bad_number", ...)
  std::size_t column = 0;   ///< 1-based byte column of the offending text
  /// What was expected, what was found; the caller prefixes "path:line:column: ".
  std::string message;
};

}  // namespace resolver
