// Small helpers that append JSON numbers to a std::string (strings:
// drivers/text/json_string.h, the one JSON string writer). JSON has no NaN or
// infinity, so non-finite numbers are written as null; finite numbers use the
// shortest text that reads back to the same value (std::to_chars).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace resolver {

void append_json_number(std::string& out, double value);
void append_json_number(std::string& out, float value);
void append_json_number(std::string& out, std::int64_t value);
/// "0x" followed by 16 lowercase hex digits, e.g. for fingerprints.
std::string hex64(std::uint64_t value);

}  // namespace resolver
