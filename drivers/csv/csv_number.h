// Numbers as CSV and scope exports write them: "-1.25", "1,25" (decimal comma),
// "1.26e-02", "133500000000000000" (a Windows FILETIME, too large for a double
// to keep every 100 ns tick). Pure; never throws.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace resolver {

/// A decimal number with `decimal` ('.' or ',') as its decimal mark and an
/// optional exponent; surrounding spaces are allowed. nullopt for anything
/// else (empty, text, "1.2.3", inf, nan).
[[nodiscard]] std::optional<double> parse_csv_number(std::string_view text, char decimal);

/// The same number times 10^scale_exp10, as an exact integer (truncated toward
/// minus infinity): [s] with scale 6 gives [us], a FILETIME in 100 ns ticks
/// with scale -1 gives [us]. nullopt when malformed or out of int64 range.
[[nodiscard]] std::optional<std::int64_t> parse_csv_scaled_integer(std::string_view text, char decimal, int scale_exp10);

}  // namespace resolver
