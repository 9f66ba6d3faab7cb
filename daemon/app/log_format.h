// Which reader a log file needs: from --format, [input] format, or the file's extension.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace resolver {

enum class LogFormat { kCandump, kAsc, kCsv };

/// "candump", "asc", "csv"; nullopt for anything else.
[[nodiscard]] std::optional<LogFormat> log_format_from_name(std::string_view name);
[[nodiscard]] std::string_view log_format_name(LogFormat format);
/// From the extension: .asc -> ASC, .csv/.txt/.tsv/.dat -> CSV, anything else (.log) -> candump.
[[nodiscard]] LogFormat log_format_for_path(std::string_view path);

}  // namespace resolver
