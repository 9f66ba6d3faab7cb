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

#include "tools/echo/lcm_type.h"

namespace resolver {

class LcmParseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses every struct in one .lcm file. `source_name` (usually the path) is
/// only used in error messages and LcmStruct::source.
/// Throws LcmParseError on any syntax or semantic error.
std::vector<LcmStruct> parse_lcm_types(std::string_view text, std::string_view source_name);

}  // namespace resolver
