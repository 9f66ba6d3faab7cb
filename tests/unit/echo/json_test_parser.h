// The echo tests' JSON parser: the project's strict reader (drivers/text/json_value.h),
// independent of resolver-echo's writer that the tests check.
#pragma once

#include "drivers/text/json_value.h"

namespace echo_test_support {

using resolver::json::Json;
using resolver::json::parse_json;

}  // namespace echo_test_support
