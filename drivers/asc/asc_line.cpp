#include "drivers/asc/asc_line.h"

#include "drivers/text/text_util.h"

#include <array>
#include <limits>
#include <string>

namespace resolver {
namespace {

struct Token {
  std::string_view text;
  std::size_t column = 0;  ///< 1-based
};
// A CANFD line: timestamp, CANFD, channel, direction, id, name, BRS, ESI, DLC,
// length, 64 data bytes and 8 trailing fields = 82; tokens past the limit are ignored.
constexpr std::size_t kMaxTokens = 96;
struct Tokens {
  std::array<Token, kMaxTokens> at{};
  std::size_t size = 0;
  [[nodiscard]] std::string_view text(std::size_t i) const { return i < size ? at[i].text : std::string_view(); }
};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

Tokens tokenize(std::string_view line) {
  Tokens t;
  std::size_t i = 0;
  while (i < line.size() && t.size < kMaxTokens) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i >= line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    t.at[t.size++] = Token{line.substr(start, i - start), start + 1};
  }
  return t;
}

using text::iequals;
using text::is_digit;
using text::istarts_with;

int digit_value(char c) {
  if (is_digit(c)) return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return 99;
}

/// An unsigned number in `base` up to `max`; nullopt for anything else.
std::optional<std::uint64_t> parse_uint(std::string_view s, int base, std::uint64_t max) {
  if (s.empty()) return std::nullopt;
  std::uint64_t v = 0;
  for (const char c : s) {
    const int d = digit_value(c);
    if (d >= base) return std::nullopt;
    v = v * static_cast<std::uint64_t>(base) + static_cast<std::uint64_t>(d);
    if (v > max) return std::nullopt;
  }
  return v;
}

constexpr std::int64_t kMicrosPerSecond = 1'000'000;
// Seconds whose microseconds still fit in int64 with room for a date (~292,000 years).
constexpr std::int64_t kMaxSeconds = std::numeric_limits<std::int64_t>::max() / kMicrosPerSecond / 2;

/// "<digits>[.<digits>]" [s] -> [us], digits past the microsecond truncated
/// (as the candump reader does: a time never moves forward by rounding).
std::optional<std::int64_t> parse_seconds_us(std::string_view s) {
  std::int64_t sec = 0;
  std::size_t i = 0;
  for (; i < s.size() && is_digit(s[i]); ++i) {
    sec = sec * 10 + (s[i] - '0');
    if (sec > kMaxSeconds) return std::nullopt;
  }
  if (i == 0) return std::nullopt;
  std::int64_t frac = 0;
  if (i < s.size()) {
    if (s[i] != '.') return std::nullopt;
    int digits = 0;
    for (++i; i < s.size(); ++i) {
      if (!is_digit(s[i])) return std::nullopt;
      if (digits++ < 6) frac = frac * 10 + (s[i] - '0');
    }
    for (; digits < 6; ++digits) frac *= 10;
  }
  return sec * kMicrosPerSecond + frac;
}

// [bytes] The largest CAN FD payload; the largest classic DLC code (9..15 mean 8 bytes).
constexpr std::uint64_t kMaxFdBytes = 64;
constexpr std::uint64_t kMaxClassicDlc = 15;

bool is_valid_fd_len(std::uint64_t n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

AscLineParser::Result problem(std::string reason, std::size_t column, std::string message) {
  return AscLineParser::Result{AscLineParser::Kind::kProblem, TextProblem{std::move(reason), column, std::move(message)}};
}
AscLineParser::Result none() { return AscLineParser::Result{}; }
AscLineParser::Result frame_ok() { return AscLineParser::Result{AscLineParser::Kind::kFrame, {}}; }

std::string quoted(std::string_view s) { return "'" + std::string(s.substr(0, 40)) + "'"; }

/// Sets the frame's ID from "<id>[x]"; a problem when it is not one.
std::optional<AscLineParser::Result> read_id(const Token& tok, int base, CanFrame& frame) {
  std::string_view text = tok.text;
  frame.extended = !text.empty() && (text.back() == 'x' || text.back() == 'X');
  if (frame.extended) text.remove_suffix(1);
  const std::uint64_t max = frame.extended ? 0x1FFFFFFFU : 0x7FFU;
  const auto id = parse_uint(text, base, max);
  if (!id) {
    return problem("bad_id", tok.column,
                   "expected a CAN ID (" + std::string(base == 16 ? "hex" : "decimal") + ", at most " +
                       (frame.extended ? "0x1FFFFFFF with 'x'" : "0x7FF; extended IDs end in 'x'") + "), found " +
                       quoted(tok.text));
  }
  frame.id = static_cast<std::uint32_t>(*id);
  return std::nullopt;
}

/// Reads `count` data bytes from token `first` on.
std::optional<AscLineParser::Result> read_data(const Tokens& t, std::size_t first, std::size_t count, int base,
                                               std::size_t line_end_column, CanFrame& frame) {
  for (std::size_t k = 0; k < count; ++k) {
    if (first + k >= t.size) {
      return problem("missing_data", line_end_column,
                     "the DLC announces " + std::to_string(count) + " data bytes, the line has " + std::to_string(k));
    }
    const Token& tok = t.at[first + k];
    const auto byte = parse_uint(tok.text, base, 0xFF);
    if (!byte) {
      return problem("bad_data_byte", tok.column,
                     "expected a data byte (" + std::string(base == 16 ? "hex 00..FF" : "decimal 0..255") + "), found " +
                         quoted(tok.text));
    }
    frame.data[k] = static_cast<std::uint8_t>(*byte);
  }
  frame.len = static_cast<std::uint8_t>(count);
  return std::nullopt;
}

/// Tokens first .. first + count - 1 exist and are data bytes.
bool all_bytes(const Tokens& t, std::size_t first, std::size_t count, int base) {
  for (std::size_t k = first; k < first + count; ++k) {
    if (k >= t.size || !parse_uint(t.text(k), base, 0xFF)) return false;
  }
  return true;
}

void set_channel(CanFrame& frame, std::uint64_t channel) {
  // ASC channels count from 1; SocketCAN interfaces from can0.
  frame.set_iface("can" + std::to_string(channel == 0 ? 0 : channel - 1));
}

constexpr std::string_view kClassicHint =
    "; ASC CAN lines look like '0.001234 1  100  Rx  d 8 01 02 03 04 05 06 07 08'";

/// The event after a line's timestamp: a frame, an error frame, or a problem.
AscLineParser::Result parse_event(const Tokens& t, std::string_view line, int base, CanFrame& frame) {
  const std::size_t end_column = line.size() + 1;
  if (t.size < 2) {
    return problem("asc_unsupported_event", end_column, "a time without an event after it" + std::string(kClassicHint));
  }
  const std::string_view what = t.text(1);
  if (iequals(what, "Start") && iequals(t.text(2), "of") && iequals(t.text(3), "measurement")) return none();

  const bool fd_line = iequals(what, "CANFD");
  // Classic: time channel id dir d|r ...; CANFD: time CANFD channel dir id ...
  const std::size_t channel_at = fd_line ? 2 : 1;
  const auto channel = parse_uint(t.text(channel_at), 10, 1'000'000);
  if (!channel) {
    // Statistics, system variables, J1939, log triggers...: events this program does not read.
    return problem("asc_unsupported_event", t.at[1].column,
                   "event " + quoted(line.substr(t.at[1].column - 1)) + " carries no CAN frame; skipped");
  }
  set_channel(frame, *channel);
  const std::size_t after_channel = channel_at + 1;
  const std::size_t error_at = fd_line ? after_channel + 1 : after_channel;  // CANFD: after the direction
  if (istarts_with(t.text(error_at), "ErrorFrame")) {
    frame.error = true;
    return frame_ok();
  }
  if (t.size <= after_channel) {
    return problem("missing_data", end_column, "nothing after the channel" + std::string(kClassicHint));
  }
  const std::size_t id_at = fd_line ? after_channel + 1 : after_channel;
  const std::size_t dir_at = fd_line ? after_channel : after_channel + 1;
  const std::string_view dir = t.text(dir_at);
  if (!fd_line && (t.text(id_at).find_first_not_of("0123456789abcdefABCDEFxX") != std::string_view::npos)) {
    return problem("asc_unsupported_event", t.at[id_at].column,
                   "event " + quoted(line.substr(t.at[1].column - 1)) + " carries no CAN frame; skipped");
  }
  if (iequals(dir, "TxRq")) {
    return problem("asc_unsupported_event", t.at[dir_at].column, "a transmit request (TxRq) is not a frame on the bus; skipped");
  }
  if (!iequals(dir, "Rx") && !iequals(dir, "Tx")) {
    return problem("bad_direction", dir_at < t.size ? t.at[dir_at].column : end_column,
                   "expected the direction Rx or Tx, found " + (dir.empty() ? std::string("end of line") : quoted(dir)));
  }
  if (id_at >= t.size) return problem("missing_data", end_column, "expected a CAN ID, found end of line");
  if (auto bad = read_id(t.at[id_at], base, frame)) return *bad;

  if (!fd_line) {
    const std::size_t type_at = dir_at + 1;
    const std::string_view type = t.text(type_at);
    if (iequals(type, "r")) {
      frame.rtr = true;
      const auto dlc = t.size > type_at + 1 ? parse_uint(t.text(type_at + 1), base, 15) : std::optional<std::uint64_t>(0);
      if (!dlc) return problem("bad_dlc", t.at[type_at + 1].column, "expected a DLC 0..F, found " + quoted(t.text(type_at + 1)));
      frame.len = static_cast<std::uint8_t>(*dlc > 8 ? 8 : *dlc);
      return frame_ok();
    }
    if (!iequals(type, "d")) {
      return problem("asc_unsupported_event", type_at < t.size ? t.at[type_at].column : end_column,
                     "expected 'd' (data) or 'r' (remote) after the direction, found " +
                         (type.empty() ? std::string("end of line") : quoted(type)) + "; skipped");
    }
    const auto dlc = parse_uint(t.text(type_at + 1), base, kMaxFdBytes);
    if (!dlc || (*dlc > kMaxClassicDlc && !is_valid_fd_len(*dlc))) {
      return problem("bad_dlc", type_at + 1 < t.size ? t.at[type_at + 1].column : end_column,
                     "expected a DLC 0..F (or, as python-can's ASCWriter writes a longer frame, its byte count "
                     "10, 14, 18, 20, 30 or 40 in hex), found " + quoted(t.text(type_at + 1)));
    }
    // python-can writes a 12-byte message not flagged FD as "d c" and its 12 bytes; a
    // classic DLC code C (CANoe) has 8 bytes and then its trailing fields.
    const bool twelve_bytes = *dlc == 12 && all_bytes(t, type_at + 2, 12, base);
    if (*dlc <= kMaxClassicDlc && !twelve_bytes) {
      // Classic DLC 9..15 still means 8 data bytes.
      if (auto bad = read_data(t, type_at + 2, *dlc > 8 ? 8 : *dlc, base, end_column, frame)) return *bad;
      return frame_ok();
    }
    // python-can's ASCWriter writes a message not flagged FD as "d <byte count in hex>"
    // (`d 40` and 64 bytes): a frame classic CAN cannot carry, so an FD frame whose flag
    // was lost. Its bytes are all on the line; read them. (python-can's own ASCReader
    // keeps only the first 8 of them, which would hide the rest from the DBC's checks.)
    if (auto bad = read_data(t, type_at + 2, *dlc, base, end_column, frame)) return *bad;
    frame.fd = true;
    return frame_ok();
  }

  // CANFD: [symbolic name] BRS ESI DLC data-length data... duration length flags ...
  std::size_t brs_at = id_at + 1;
  const std::string_view maybe_brs = t.text(brs_at);
  if (!(maybe_brs.size() == 1 && is_digit(maybe_brs[0]))) ++brs_at;  // a symbolic name
  const std::string_view brs = t.text(brs_at);
  const std::string_view esi = t.text(brs_at + 1);
  const auto dlc = parse_uint(t.text(brs_at + 2), 16, 15);
  const auto length = parse_uint(t.text(brs_at + 3), 10, 64);
  if ((brs != "0" && brs != "1") || (esi != "0" && esi != "1") || !dlc || !length || !is_valid_fd_len(*length)) {
    return problem("bad_fd_fields", brs_at < t.size ? t.at[brs_at].column : end_column,
                   "expected '<BRS 0|1> <ESI 0|1> <DLC hex> <data length 0..8,12,16,20,24,32,48,64>' after the CAN FD "
                   "ID, found " + quoted(brs_at < t.size ? line.substr(t.at[brs_at].column - 1) : std::string_view()));
  }
  const std::size_t data_at = brs_at + 4;
  if (auto bad = read_data(t, data_at, *length, base, end_column, frame)) return *bad;
  // Flags (hex) follow the message duration and length; bit 12 (EDL) clear
  // marks a classic frame logged on an FD channel.
  const auto flags = parse_uint(t.text(data_at + *length + 2), 16, 0xFFFFFFFFU);
  frame.fd = !(flags && (*flags & 0x1000U) == 0);
  if (!frame.fd && frame.len > 8) {
    return problem("bad_fd_fields", t.at[data_at + *length + 2].column,
                   "flags say a classic frame (EDL bit 0x1000 clear) but it has " + std::to_string(frame.len) + " bytes");
  }
  if (frame.fd) frame.fd_flags = static_cast<std::uint8_t>((brs == "1" ? 0x01U : 0U) | (esi == "1" ? 0x02U : 0U));
  return frame_ok();
}

}  // namespace

AscLineParser::Result AscLineParser::parse(std::string_view line, CanFrame& frame) {
  const Tokens t = tokenize(line);
  if (t.size == 0) return none();
  const std::string_view first = t.text(0);
  if (is_digit(first.front())) {
    const auto time_us = parse_seconds_us(first);
    if (!time_us) {
      return problem("bad_timestamp", t.at[0].column,
                     "expected a time in seconds like 0.001234, found " + quoted(first));
    }
    // Relative timestamps count from the previous event (every event, frame or not).
    last_event_us_ = relative_ ? last_event_us_ + *time_us : *time_us;
    frame = CanFrame{};
    Result r = parse_event(t, line, base_, frame);
    frame.timestamp_us = start_us_.value_or(0) + last_event_us_;
    return r;
  }
  if (first.starts_with("//")) return none();
  if (iequals(first, "date")) {
    const std::size_t rest = t.size > 1 ? t.at[1].column - 1 : line.size();
    start_us_ = parse_asc_date(line.substr(rest));
    if (!start_us_) {
      return problem("asc_bad_date", rest + 1,
                     "cannot read the date header " + quoted(line.substr(rest)) +
                         " (expected e.g. 'Wed Jan 10 10:47:09.123 am 2024'); times count from the start of measurement");
    }
    return none();
  }
  if (iequals(first, "base")) {
    if (iequals(t.text(1), "hex")) {
      base_ = 16;
    } else if (iequals(t.text(1), "dec")) {
      base_ = 10;
    } else {
      return problem("asc_bad_header", t.size > 1 ? t.at[1].column : line.size() + 1,
                     "expected 'base hex' or 'base dec', found " + quoted(t.text(1)));
    }
    if (t.size > 2) {
      if (!iequals(t.text(2), "timestamps") || !(iequals(t.text(3), "absolute") || iequals(t.text(3), "relative"))) {
        return problem("asc_bad_header", t.at[2].column,
                       "expected 'timestamps absolute' or 'timestamps relative', found " +
                           quoted(line.substr(t.at[2].column - 1)));
      }
      relative_ = iequals(t.text(3), "relative");
    }
    return none();
  }
  if (iequals(first, "begin") && iequals(t.text(1), "triggerblock")) {
    // The first block's date is when its times start (python-can writes the
    // date header when converting, this one from the first frame); later
    // blocks' times still count from the start of measurement.
    if (!block_seen_ && t.size > 2) {
      if (const auto block_start = parse_asc_date(line.substr(t.at[2].column - 1))) start_us_ = block_start;
    }
    block_seen_ = true;
    return none();
  }
  if ((iequals(first, "internal") && iequals(t.text(1), "events")) ||
      (iequals(first, "no") && iequals(t.text(1), "internal")) ||
      (iequals(first, "end") && iequals(t.text(1), "triggerblock"))) {
    return none();
  }
  return problem("asc_unknown_line", t.at[0].column,
                 "not a Vector ASC line: expected a header (date, base, internal events logged, Begin/End "
                 "Triggerblock, // comment) or an event starting with its time, found " + quoted(first));
}

namespace {

/// Days since 1970-01-01 of a civil date (proleptic Gregorian; H. Hinnant's algorithm).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

std::optional<unsigned> month_number(std::string_view name) {
  // English, and the German ones that differ (CANoe writes the locale's names).
  static constexpr std::array<std::pair<std::string_view, unsigned>, 17> kMonths{{
      {"jan", 1}, {"feb", 2}, {"mar", 3}, {"apr", 4}, {"may", 5}, {"jun", 6}, {"jul", 7}, {"aug", 8},
      {"sep", 9}, {"oct", 10}, {"nov", 11}, {"dec", 12}, {"m\xC3\xA4r", 3}, {"mrz", 3}, {"mai", 5}, {"okt", 10},
      {"dez", 12}}};
  for (const auto& [n, m] : kMonths) {
    if (istarts_with(name, n)) return m;
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::int64_t> parse_asc_date(std::string_view text) {
  const Tokens t = tokenize(text);
  std::size_t i = 0;
  std::optional<unsigned> month;
  for (; i < t.size && i < 2 && !month; ++i) month = month_number(t.text(i));  // a weekday may come first
  if (!month || i + 2 > t.size) return std::nullopt;
  const auto day = parse_uint(t.text(i), 10, 31);
  // hh:mm:ss[.fff]
  const std::string_view clock = t.text(i + 1);
  if (!day || *day == 0 || clock.size() < 8 || clock[2] != ':' || clock[5] != ':') return std::nullopt;
  const auto hh = parse_uint(clock.substr(0, 2), 10, 23);
  const auto mm = parse_uint(clock.substr(3, 2), 10, 59);
  const auto ss_us = parse_seconds_us(clock.substr(6));
  if (!hh || !mm || !ss_us || *ss_us >= 61 * kMicrosPerSecond) return std::nullopt;
  std::uint64_t hour = *hh;
  std::size_t year_at = i + 2;
  const std::string_view ampm = t.text(year_at);
  if (iequals(ampm, "am") || iequals(ampm, "pm")) {
    if (hour < 1 || hour > 12) return std::nullopt;
    hour = hour % 12 + (iequals(ampm, "pm") ? 12 : 0);
    ++year_at;
  }
  const auto year = parse_uint(t.text(year_at), 10, 9999);
  if (!year || *year < 1970) return std::nullopt;
  const std::int64_t days = days_from_civil(static_cast<std::int64_t>(*year), *month, static_cast<unsigned>(*day));
  const auto seconds = days * 86400 + static_cast<std::int64_t>(hour * 3600 + *mm * 60);
  return seconds * kMicrosPerSecond + *ss_us;
}

}  // namespace resolver
