// .lcm text -> LcmStruct descriptions, following lcm-gen's grammar:
//
//   package NAME ;
//   struct NAME { MEMBER... }
//   MEMBER := TYPE NAME DIMS { , NAME DIMS } ;
//           | const TYPE NAME = VALUE { , NAME = VALUE } ;
//   DIMS   := { [ INTEGER | EARLIER_INTEGER_MEMBER ] }
//
// with // and /* */ comments anywhere. Enums (deprecated in LCM) are rejected.
// Parsing never crashes on bad input: every problem throws LcmParseError whose
// message names the source, line and column and says how to fix it.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/errors.h"
#include "tools/echo/lcm_type.h"

namespace resolver {

/// A .lcm file (or --types directory) that cannot be used: the user's configuration,
/// so the rule's InputError with Fault::kUsage (exit 2); what() is the message as given.
class LcmParseError : public InputError {
 public:
  explicit LcmParseError(const std::string& message) : InputError(Fault::kUsage, message) {}
};

/// Parses every struct in one .lcm file. `source_name` (usually the path) is
/// only used in error messages and LcmStruct::source.
/// Throws LcmParseError on any syntax or semantic error.
std::vector<LcmStruct> parse_lcm_types(std::string_view text, std::string_view source_name);

}  // namespace resolver
