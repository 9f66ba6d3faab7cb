// Counter names for LogLineError. They appear in health_t and run reports, so
// they never change once published.
#include "drivers/candump/candump_line.h"

namespace resolver {

std::string_view to_string(LogLineError error) {
  switch (error) {
    case LogLineError::kMissingTimestamp: return "missing_timestamp";
    case LogLineError::kBadTimestamp: return "bad_timestamp";
    case LogLineError::kMissingInterface: return "missing_interface";
    case LogLineError::kMissingFrame: return "missing_frame";
    case LogLineError::kBadId: return "bad_id";
    case LogLineError::kBadSeparator: return "bad_separator";
    case LogLineError::kBadHex: return "bad_hex";
    case LogLineError::kOddNibbles: return "odd_nibbles";
    case LogLineError::kTooLong: return "dlc_too_long";
    case LogLineError::kBadFdFlags: return "bad_fd_flags";
    case LogLineError::kLineTooLong: return "line_too_long";
  }
  // Only reachable with a value cast from outside the enum's range.
  return "unknown_log_line_error";
}

}  // namespace resolver
