// Small helpers that append JSON text to a std::string. JSON has no NaN or
// infinity, so non-finite numbers are written as null; finite numbers use the
// shortest text that reads back to the same value (std::to_chars).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace resolver {

/// Appends `text` as a quoted JSON string. Control characters and invalid
/// UTF-8 bytes are escaped (\u00XX and U+FFFD), so the output is always valid JSON.
void append_json_string(std::string& out, std::string_view text);
void append_json_number(std::string& out, double value);
void append_json_number(std::string& out, float value);
void append_json_number(std::string& out, std::int64_t value);
/// "0x" followed by 16 lowercase hex digits, e.g. for fingerprints.
std::string hex64(std::uint64_t value);

}  // namespace resolver
