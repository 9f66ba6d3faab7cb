// One line of a candump -l log (the can-utils "log file" format), both ways.
//
//   (1699999999.123456) can0 123#DEADBEEF        classic, standard 11-bit id
//   (1699999999.123456) can0 1ABCDEF0#0102       classic, extended 29-bit id (8 digits)
//   (1699999999.123456) can0 123#R   123#R5      remote request, optional length digit
//   (1699999999.123456) can0 123##1AABB          CAN FD: '##', flags nibble (BRS=1, ESI=2), data
//   (1699999999.123456) can0 20000080#00...      error frame: 8-digit id with CAN_ERR_FLAG
//
// What the parser accepts beyond what candump writes, and why:
//   - any number of fraction digits in the timestamp, or none ("(166)"): logs
//     from other tools (SavvyCAN, python-can) do this. Digits past the
//     microsecond are truncated, not rounded, so a time never moves forward.
//   - runs of spaces/tabs between fields: candump right-aligns interface names
//     when it logs several interfaces ("%*s").
//   - a trailing direction flag " R" / " T" (candump -x, python-can's writer);
//     it is checked and dropped, CanFrame has no field for it.
//   - '.' between data bytes ("123#11.22.33"): cansend/canplayer syntax.
//   - "_X" after 8 classic data bytes (len8_dlc, DLC 9..15): the raw DLC is
//     dropped because CanFrame has no field for it; the data is kept.
//   - FD flags nibble 0..7: bit 2 (CANFD_FDF) is set by newer kernels and is
//     implied by CanFrame::fd, so only BRS and ESI are kept.
//   - error frames with fewer than 8 data bytes (python-can writes whatever
//     its Message holds, often nothing).
//   - trailing whitespace and '\r' (logs copied through Windows tools).
//
// All functions here are pure (no I/O) and never throw on bad input; the
// parser does not allocate on success, so a reader parses millions of lines/s.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "daemon/core/errors.h"
#include "drivers/can_frame.h"

namespace resolver {

/// Longest line [bytes, without the newline] the reader accepts. A real
/// candump line is at most ~200 bytes (64-byte FD payload = 128 hex digits),
/// so anything longer is garbage (e.g. a binary file read by mistake).
inline constexpr std::size_t kMaxCandumpLineLength = 4096;

/// Why a line was rejected. The order is fixed: other code indexes counters by it.
enum class LogLineError : std::uint8_t {
  kMissingTimestamp,       ///< line does not start with '('
  kBadTimestamp,           ///< not "(<digits>[.<digits>])", negative or too large
  kMissingInterface,       ///< no interface name after the timestamp (or one > 15 chars)
  kMissingFrame,           ///< no "<id>#<data>" after the interface
  kBadId,                  ///< id not 3 or 8 hex digits, or out of range
  kBadSeparator,           ///< no '#' after the id, or junk after the frame
  kBadHex,                 ///< a non-hex character in the data
  kOddNibbles,             ///< a data byte with only one hex digit
  kTooLong,                ///< > 8 classic / > 64 FD bytes, or not a valid FD length
  kBadFdFlags,             ///< '##' without a flags nibble 0..7
  kLineTooLong,            ///< more than kMaxCandumpLineLength bytes
};
inline constexpr std::size_t kLogLineErrorCount = 11;
inline constexpr std::array<LogLineError, kLogLineErrorCount> kAllLogLineErrors{
    LogLineError::kMissingTimestamp, LogLineError::kBadTimestamp, LogLineError::kMissingInterface,
    LogLineError::kMissingFrame,     LogLineError::kBadId,        LogLineError::kBadSeparator,
    LogLineError::kBadHex,           LogLineError::kOddNibbles,   LogLineError::kTooLong,
    LogLineError::kBadFdFlags,       LogLineError::kLineTooLong};

/// Stable snake_case counter name: "missing_timestamp", "bad_timestamp",
/// "missing_interface", "missing_frame", "bad_id", "bad_separator", "bad_hex",
/// "odd_nibbles", "dlc_too_long", "bad_fd_flags", "line_too_long". (A timestamp
/// that goes back is no line error: the sample clock counts it as timestamp_step_back.)
[[nodiscard]] std::string_view to_string(LogLineError error);

struct LogLineProblem {
  LogLineError kind = LogLineError::kMissingTimestamp;
  /// 1-based column (byte offset + 1) of the first offending character; for
  /// "found end of line" problems, one past the last character.
  std::size_t column = 0;
  /// Human text: what was expected, what was found, what to do. It does not
  /// name the file or line; the caller prefixes "path:line:column: ".
  std::string message;
};

/// Parses one line (with or without its '\n'). Returns nullopt on success and
/// fills every field of `frame` (timestamp_us, iface, id, extended, rtr,
/// error, fd, fd_flags, len, data; data bytes past len are zero). On failure
/// returns the problem; `frame` is then unspecified. Never throws except
/// std::bad_alloc while building a problem's message.
[[nodiscard]] std::optional<LogLineProblem> parse_candump_line(std::string_view line, CanFrame& frame);

/// Returns when `frame` can be written as a candump line that parse_candump_line
/// (and canplayer) reads back identically; else throws InputError (Fault::kUsage:
/// the frame came from the caller's options) "WHERE: cannot log this frame: WHY",
/// `where` being the log and the line the frame would have taken. Checks: a
/// timestamp >= 0, a non-empty interface name without blanks or control
/// bytes, the id range (11/29 bits), len (<= 8 classic, a valid FD length),
/// FD flags only BRS/ESI and only on FD frames, no RTR on FD or error frames.
void check_loggable(const CanFrame& frame, const Where& where = {});

/// Appends the frame exactly as `candump -l` logs it, including the trailing
/// '\n': "(%010lu.%06lu) <iface> <frame>\n" with upper-case hex, e.g.
/// "(1699999999.123456) can0 123#DEADBEEF\n".
/// Precondition: check_loggable(frame) does not throw; otherwise the output is
/// clamped like candump's (len cut to 8/64, id masked, '-' for an empty
/// interface) and may not read back the same. Does not allocate when `out`
/// has 256 bytes of spare capacity.
void append_candump_line(const CanFrame& frame, std::string& out);

}  // namespace resolver
