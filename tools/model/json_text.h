// JSON text for the report page's data and the exports: strings escaped for JSON
// and for an HTML <script> element (no "</script>" can close it early), numbers
// with a fixed precision and null for NaN and infinity (JSON has neither).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace resolver::json {

/// `s` as a JSON string literal; <, > and & as \u escapes (safe inside <script>).
[[nodiscard]] std::string str(std::string_view s);

/// `v` with `digits` significant digits, or null when not finite.
[[nodiscard]] std::string num(double v, int digits = 9);

/// [a,b,...] of num(v, digits).
[[nodiscard]] std::string array(const std::vector<double>& v, int digits = 6);

}  // namespace resolver::json
