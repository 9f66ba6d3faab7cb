// parse_candump_line: one candump -l line -> CanFrame, or a typed problem.
//
// Hot path of offline replay (target >= 2 M frames/s on one core): a
// table-driven hex decoder, integer timestamp arithmetic (no strtod, whose
// rounding would also move times by a microsecond), and no allocation unless
// the line is bad. Left-to-right: the first problem found is the one reported.
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "drivers/candump/candump_line.h"

namespace resolver {
namespace {

constexpr std::uint32_t kErrFlag = 0x20000000U;  // CAN_ERR_FLAG (linux/can.h)
constexpr std::uint32_t kEffMask = 0x1FFFFFFFU;  // CAN_EFF_MASK: 29-bit id
constexpr std::uint32_t kSffMask = 0x000007FFU;  // CAN_SFF_MASK: 11-bit id
constexpr std::uint8_t kNotHex = 0xFF;

constexpr std::array<std::uint8_t, 256> make_hex_table() {
  std::array<std::uint8_t, 256> table{};
  table.fill(kNotHex);
  for (int c = 0; c < 10; ++c) table[static_cast<std::size_t>('0' + c)] = static_cast<std::uint8_t>(c);
  for (int c = 0; c < 6; ++c) {
    table[static_cast<std::size_t>('A' + c)] = static_cast<std::uint8_t>(10 + c);
    table[static_cast<std::size_t>('a' + c)] = static_cast<std::uint8_t>(10 + c);
  }
  return table;
}
constexpr std::array<std::uint8_t, 256> kHexTable = make_hex_table();

std::uint8_t hex_value(char c) { return kHexTable[static_cast<unsigned char>(c)]; }
bool is_blank(char c) { return c == ' ' || c == '\t'; }
bool is_space(char c) { return is_blank(c) || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

bool is_valid_fd_len(std::size_t n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

// "0x"-less upper-case hex of `value`, at least `width` digits, for messages.
std::string hex_text(std::uint32_t value, int width) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string text;
  for (int shift = 28; shift >= 0; shift -= 4) {
    const auto nibble = (value >> static_cast<unsigned>(shift)) & 0xFU;
    if (!text.empty() || nibble != 0 || shift < 4 * width) text.push_back(kDigits[nibble]);
  }
  return text;
}

constexpr std::int64_t kMicrosPerSecond = 1'000'000;
// Largest whole second whose microsecond count still fits in int64 (~292,000 years).
constexpr std::int64_t kMaxSeconds = (std::numeric_limits<std::int64_t>::max() - (kMicrosPerSecond - 1)) /
                                     kMicrosPerSecond;

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// How a character (or its absence) is shown in a message.
std::string found(std::string_view s, std::size_t i, std::string_view end_name = "end of line") {
  if (i >= s.size()) return std::string(end_name);
  const auto c = static_cast<unsigned char>(s[i]);
  if (c >= 0x20 && c < 0x7F) return std::string("'") + s[i] + "'";
  return "byte 0x" + hex_text(c, 2);
}

LogLineProblem problem(LogLineError kind, std::size_t index, std::string message) {
  return LogLineProblem{kind, index + 1, std::move(message)};
}

constexpr std::string_view kFormatHint = "; candump -l lines look like '(1699999999.123456) can0 123#DEADBEEF'";

// Parses "(<sec>[.<frac>])" starting at s[i]; advances i past ')'.
std::optional<LogLineProblem> parse_timestamp(std::string_view s, std::size_t& i, std::int64_t& timestamp_us) {
  if (i >= s.size() || s[i] != '(') {
    return problem(LogLineError::kMissingTimestamp, i,
                   "expected '(' opening the timestamp, found " + found(s, i) + std::string(kFormatHint));
  }
  ++i;
  const std::size_t sec_start = i;
  std::int64_t seconds = 0;
  while (i < s.size() && is_digit(s[i])) {
    seconds = seconds * 10 + (s[i] - '0');
    if (seconds > kMaxSeconds) {
      return problem(LogLineError::kBadTimestamp, sec_start,
                     "timestamp seconds are too large for a microsecond int64 (more than " +
                         std::to_string(kMaxSeconds) + " s); check the log's clock or edit the line");
    }
    ++i;
  }
  if (i == sec_start) {
    return problem(LogLineError::kBadTimestamp, i,
                   "expected the timestamp's seconds (decimal digits, not negative), found " + found(s, i) +
                       std::string(kFormatHint));
  }
  std::int64_t micros = 0;
  if (i < s.size() && s[i] == '.') {
    ++i;
    int used = 0;  // fraction digits past the 6th are truncated (see header)
    while (i < s.size() && is_digit(s[i])) {
      if (used < 6) {
        micros = micros * 10 + (s[i] - '0');
        ++used;
      }
      ++i;
    }
    for (; used < 6; ++used) micros *= 10;
  }
  if (i >= s.size() || s[i] != ')') {
    return problem(LogLineError::kBadTimestamp, i,
                   "expected a digit, '.' or the closing ')' of the timestamp, found " + found(s, i) +
                       std::string(kFormatHint));
  }
  ++i;
  timestamp_us = seconds * kMicrosPerSecond + micros;
  return std::nullopt;
}

// Everything after "<id>#": data, "R[len]", or "#<flags><data>". `k` is the
// index after the first '#', `end` the end of the frame token.
std::optional<LogLineProblem> parse_payload(std::string_view s, std::size_t k, std::size_t end, CanFrame& frame) {
  if (k < end && (s[k] == 'R' || s[k] == 'r')) {
    if (frame.error) {
      return problem(LogLineError::kBadHex, k,
                     "expected the error frame's data bytes, found a remote request 'R'; error frames are never "
                     "remote requests, fix the id or the data");
    }
    frame.rtr = true;
    ++k;
    if (k < end && is_digit(s[k])) {
      const int len = s[k] - '0';
      if (len > static_cast<int>(CanFrame::kMaxClassicLen)) {
        return problem(LogLineError::kTooLong, k,
                       "remote request length " + std::to_string(len) + " is above 8; use R0..R8");
      }
      frame.len = static_cast<std::uint8_t>(len);
      ++k;
    }
    if (k < end) {
      return problem(LogLineError::kBadHex, k,
                     "unexpected " + found(s, k) + " after the remote request; expected 'R' or 'R<length 0-8>'");
    }
    return std::nullopt;
  }

  if (k < end && s[k] == '#') {
    if (frame.error) {
      return problem(LogLineError::kBadSeparator, k,
                     "error frames are classic CAN, found '##' (CAN FD) after an error-frame id; use one '#'");
    }
    ++k;
    const std::uint8_t flags = k < end ? hex_value(s[k]) : kNotHex;
    if (flags > 7) {
      return problem(LogLineError::kBadFdFlags, k,
                     "expected the CAN FD flags nibble 0-7 (BRS=1, ESI=2, FDF=4) after '##', found " +
                         found(s, k, "end of frame") + "; write e.g. '123##1AABB' for BRS with data AA BB");
    }
    frame.fd = true;
    frame.fd_flags = static_cast<std::uint8_t>(flags & 0x03U);  // FDF (4) is implied by fd
    ++k;
  }

  // Validate first, decode second: the data array is only written once the
  // length is known to fit.
  std::size_t digits = 0;
  std::size_t p = k;
  for (; p < end; ++p) {
    const char c = s[p];
    if (hex_value(c) != kNotHex) {
      ++digits;
    } else if (c == '.') {
      if (digits % 2 != 0) {
        return problem(LogLineError::kOddNibbles, p - 1,
                       "data byte '" + std::string(1, s[p - 1]) +
                           "' has one hex digit; every byte needs two (write 0A, not A)");
      }
    } else if (c == '_' && !frame.fd) {
      break;  // len8_dlc suffix, checked below
    } else {
      return problem(LogLineError::kBadHex, p,
                     "expected a hex digit 0-9/A-F in the data, found " + found(s, p) +
                         "; data is two hex digits per byte, e.g. 123#DEADBEEF");
    }
  }
  if (digits % 2 != 0) {
    return problem(LogLineError::kOddNibbles, p - 1,
                   "odd number of hex digits (" + std::to_string(digits) +
                       ") in the data: the last byte has one digit; every byte needs two (write 0A, not A)");
  }
  const std::size_t bytes = digits / 2;
  if (!frame.fd && bytes > CanFrame::kMaxClassicLen) {
    return problem(LogLineError::kTooLong, k,
                   "classic CAN frame has " + std::to_string(bytes) +
                       " data bytes, at most 8 are allowed; CAN FD frames are written '<id>##<flags><data>'");
  }
  if (frame.fd && bytes > CanFrame::kMaxFdLen) {
    return problem(LogLineError::kTooLong, k,
                   "CAN FD frame has " + std::to_string(bytes) + " data bytes, at most 64 are allowed");
  }
  if (frame.fd && !is_valid_fd_len(bytes)) {
    return problem(LogLineError::kTooLong, k,
                   "CAN FD frame has " + std::to_string(bytes) +
                       " data bytes, not a valid FD length (0-8, 12, 16, 20, 24, 32, 48, 64); pad the data to "
                       "the next valid length");
  }
  if (p < end) {  // "_<dlc>": raw DLC 9..F of an 8-byte classic frame (len8_dlc)
    const std::uint8_t dlc = p + 1 < end ? hex_value(s[p + 1]) : kNotHex;
    if (bytes != CanFrame::kMaxClassicLen || dlc < 9 || dlc > 15 || p + 2 != end) {
      return problem(LogLineError::kBadHex, p,
                     "unexpected '_' in the data; '_<dlc 9-F>' may only follow exactly 8 classic data bytes");
    }
  }

  std::uint8_t* out = frame.data.data();
  for (std::size_t q = k; q < p;) {
    if (s[q] == '.') {
      ++q;
      continue;
    }
    *out++ = static_cast<std::uint8_t>((hex_value(s[q]) << 4U) | hex_value(s[q + 1]));
    q += 2;
  }
  frame.len = static_cast<std::uint8_t>(bytes);
  return std::nullopt;
}

// "<id>#..." in s[begin, end).
std::optional<LogLineProblem> parse_frame(std::string_view s, std::size_t begin, std::size_t end, CanFrame& frame) {
  std::size_t j = begin;
  std::uint32_t raw = 0;
  std::size_t digits = 0;
  while (j < end && hex_value(s[j]) != kNotHex) {
    if (digits < 8) raw = (raw << 4U) | hex_value(s[j]);
    ++digits;
    ++j;
  }
  const bool at_hash = j < end && s[j] == '#';
  if (digits != 3 && digits != 8) {
    if (j < end && !at_hash) {
      return problem(LogLineError::kBadId, j,
                     "expected a hex digit in the CAN id, found " + found(s, j, "end of frame") +
                         "; ids are 3 hex digits (standard) or 8 (extended), then '#'");
    }
    return problem(LogLineError::kBadId, begin,
                   "CAN id '" + std::string(s.substr(begin, j - begin)) + "' has " + std::to_string(digits) +
                       " hex digits; expected 3 (standard, e.g. 123#) or 8 (extended, e.g. 1ABCDEF0#)");
  }
  if (!at_hash) {
    return problem(LogLineError::kBadSeparator, j,
                   "expected '#' after the CAN id, found " + found(s, j, "end of frame") +
                       "; frames are written <id>#<data>");
  }

  frame.id = 0;
  frame.extended = false;
  frame.rtr = false;
  frame.error = false;
  frame.fd = false;
  frame.fd_flags = 0;
  frame.len = 0;
  frame.data.fill(0);
  if (digits == 3) {
    if (raw > kSffMask) {
      return problem(LogLineError::kBadId, begin,
                     "standard CAN id 0x" + hex_text(raw, 3) +
                         " is above 0x7FF (11 bits); write extended ids with 8 hex digits");
    }
    frame.id = raw;
  } else if ((raw & kErrFlag) != 0) {
    if ((raw & ~(kErrFlag | kEffMask)) != 0) {
      return problem(LogLineError::kBadId, begin,
                     "error frame id 0x" + hex_text(raw, 8) +
                         " also has the EFF or RTR flag bit set; error ids are 0x20000000 | class bits");
    }
    frame.error = true;
    frame.id = raw & kEffMask;
  } else {
    if (raw > kEffMask) {
      return problem(LogLineError::kBadId, begin,
                     "extended CAN id 0x" + hex_text(raw, 8) +
                         " is above 0x1FFFFFFF (29 bits); check the id");
    }
    frame.extended = true;
    frame.id = raw;
  }
  return parse_payload(s, j + 1, end, frame);
}

}  // namespace

std::optional<LogLineProblem> parse_candump_line(std::string_view line, CanFrame& frame) {
  if (line.size() > kMaxCandumpLineLength) {
    return problem(LogLineError::kLineTooLong, kMaxCandumpLineLength,
                   "line is " + std::to_string(line.size()) + " bytes long, a candump line has at most " +
                       std::to_string(kMaxCandumpLineLength) + "; is this really a candump -l log?");
  }
  std::size_t size = line.size();
  while (size > 0 && is_space(line[size - 1])) --size;
  const std::string_view s = line.substr(0, size);

  std::size_t i = 0;
  while (i < s.size() && is_blank(s[i])) ++i;
  std::int64_t timestamp_us = 0;
  if (auto p = parse_timestamp(s, i, timestamp_us)) return p;

  const std::size_t after_timestamp = i;
  while (i < s.size() && is_blank(s[i])) ++i;
  if (i >= s.size()) {
    return problem(LogLineError::kMissingInterface, i,
                   "expected the interface name (e.g. can0) after the timestamp, found end of line" +
                       std::string(kFormatHint));
  }
  if (i == after_timestamp) {
    return problem(LogLineError::kMissingInterface, i,
                   "expected a space and the interface name after the timestamp's ')', found " + found(s, i) +
                       std::string(kFormatHint));
  }
  const std::size_t iface_begin = i;
  while (i < s.size() && !is_blank(s[i])) ++i;
  const std::string_view iface = s.substr(iface_begin, i - iface_begin);

  while (i < s.size() && is_blank(s[i])) ++i;
  if (i >= s.size()) {
    if (iface.find('#') != std::string_view::npos) {
      return problem(LogLineError::kMissingInterface, iface_begin,
                     "expected the interface name before the frame, found the frame '" + std::string(iface) +
                         "' right after the timestamp" + std::string(kFormatHint));
    }
    return problem(LogLineError::kMissingFrame, i,
                   "expected the frame '<id>#<data>' after interface '" + std::string(iface) +
                       "', found end of line" + std::string(kFormatHint));
  }
  for (std::size_t k = 0; k < iface.size(); ++k) {
    const auto ch = static_cast<unsigned char>(iface[k]);
    if (ch < 0x20 || ch >= 0x7F) {
      // Found by fuzzing: a NUL, control or non-ASCII byte would be cut or mangled in the
      // stored name, so the frame could not be written back as the same line.
      return problem(LogLineError::kMissingInterface, iface_begin + k,
                     "interface name contains the byte 0x" + std::string(1, "0123456789abcdef"[ch >> 4U]) +
                         std::string(1, "0123456789abcdef"[ch & 0xFU]) +
                         "; interface names are printable ASCII (e.g. can0): the log line is corrupted");
    }
  }
  if (iface.size() >= CanFrame::kMaxIfaceLen) {
    return problem(LogLineError::kMissingInterface, iface_begin,
                   "interface name '" + std::string(iface) + "' has " + std::to_string(iface.size()) +
                       " characters, Linux allows at most 15 (IFNAMSIZ); shorten it in the log");
  }

  const std::size_t frame_begin = i;
  while (i < s.size() && !is_blank(s[i])) ++i;
  if (auto p = parse_frame(s, frame_begin, i, frame)) return p;

  // Optional direction flag: candump -x and python-can append " R" / " T".
  while (i < s.size() && is_blank(s[i])) ++i;
  if (i < s.size()) {
    const char c = s[i];
    const bool direction = (c == 'R' || c == 'T' || c == 'r' || c == 't') && i + 1 == s.size();
    if (!direction) {
      return problem(LogLineError::kBadSeparator, i,
                     "unexpected text after the frame, found " + found(s, i) +
                         "; expected end of line or a direction flag R/T");
    }
  }

  frame.timestamp_us = timestamp_us;
  frame.set_iface(iface);
  return std::nullopt;
}

}  // namespace resolver
