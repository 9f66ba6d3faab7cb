// JSON string literals, written one way for every program: resolverd's run
// report, the calibration table, resolver-model's reports and exports,
// resolver-sim's truth file and resolver-echo's messages (pure, no I/O).
#pragma once

#include <string>
#include <string_view>

namespace resolver::text {

enum class JsonEscape {
  plain,        ///< what JSON requires, and nothing more
  script_safe,  ///< also <, > and & as \u escapes, so the literal cannot close an HTML <script> element
};

/// Appends `s` to `out` as a quoted JSON string literal. Cannot fail and drops
/// nothing: " and \ are escaped; \b \f \n \r \t take their short forms; every
/// other control character (U+0000..U+001F and U+007F) becomes \u00xx; valid
/// UTF-8 is copied as it is. JSON text must be UTF-8, so each byte that is not
/// part of a valid UTF-8 sequence becomes \ufffd, visibly.
void append_json_string(std::string& out, std::string_view s, JsonEscape how = JsonEscape::plain);

/// `s` as a quoted JSON string literal (append_json_string's rules).
[[nodiscard]] std::string json_string(std::string_view s, JsonEscape how = JsonEscape::plain);

}  // namespace resolver::text
