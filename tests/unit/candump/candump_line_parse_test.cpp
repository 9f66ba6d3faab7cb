// parse_candump_line: every form candump -l (and friends) writes, and one line
// per LogLineError with the column and message it must report.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "drivers/candump/candump_line.h"

namespace resolver {
namespace {

CanFrame parse_ok(const std::string& line) {
  CanFrame f;
  f.data.fill(0xEE);  // stale bytes must not survive
  const auto problem = parse_candump_line(line, f);
  EXPECT_FALSE(problem.has_value()) << line << " -> " << (problem ? problem->message : "");
  return f;
}

TEST(CandumpLineParse, ClassicStandardFrame) {
  const CanFrame f = parse_ok("(1699999999.123456) can0 123#DEADBEEF");
  EXPECT_EQ(f.timestamp_us, 1699999999LL * 1000000 + 123456);
  EXPECT_EQ(f.iface_name(), "can0");
  EXPECT_EQ(f.id, 0x123U);
  EXPECT_FALSE(f.extended);
  EXPECT_FALSE(f.rtr || f.error || f.fd);
  ASSERT_EQ(f.len, 4);
  EXPECT_EQ(f.data[0], 0xDE);
  EXPECT_EQ(f.data[1], 0xAD);
  EXPECT_EQ(f.data[2], 0xBE);
  EXPECT_EQ(f.data[3], 0xEF);
  for (std::size_t i = f.len; i < f.data.size(); ++i) EXPECT_EQ(f.data[i], 0) << "byte " << i;
}

TEST(CandumpLineParse, LowerCaseHexAndEmptyData) {
  const CanFrame f = parse_ok("(5.000001) vcan0 7ff#0a0b");
  EXPECT_EQ(f.id, 0x7FFU);
  ASSERT_EQ(f.len, 2);
  EXPECT_EQ(f.data[0], 0x0A);
  EXPECT_EQ(f.data[1], 0x0B);
  EXPECT_EQ(f.timestamp_us, 5000001);
  EXPECT_EQ(parse_ok("(5.0) can0 000#").len, 0);
}

TEST(CandumpLineParse, ExtendedId) {
  const CanFrame f = parse_ok("(1.5) can1 1ABCDEF0#0102");
  EXPECT_TRUE(f.extended);
  EXPECT_EQ(f.id, 0x1ABCDEF0U);
  EXPECT_EQ(f.len, 2);
  // An 8-digit id is extended even when its value would fit in 11 bits.
  const CanFrame small = parse_ok("(1.5) can1 00000123#");
  EXPECT_TRUE(small.extended);
  EXPECT_EQ(small.id, 0x123U);
}

TEST(CandumpLineParse, RemoteRequests) {
  const CanFrame plain = parse_ok("(2.0) can0 123#R");
  EXPECT_TRUE(plain.rtr);
  EXPECT_EQ(plain.len, 0);
  const CanFrame with_len = parse_ok("(2.0) can0 123#R5");
  EXPECT_TRUE(with_len.rtr);
  EXPECT_EQ(with_len.len, 5);
  const CanFrame ext = parse_ok("(2.0) can0 12345678#r8");
  EXPECT_TRUE(ext.rtr && ext.extended);
  EXPECT_EQ(ext.len, 8);
}

TEST(CandumpLineParse, CanFdFramesWithFlags) {
  const CanFrame none = parse_ok("(3.0) can0 123##0AABB");
  EXPECT_TRUE(none.fd);
  EXPECT_EQ(none.fd_flags, 0);
  EXPECT_EQ(none.len, 2);
  EXPECT_EQ(none.data[0], 0xAA);
  EXPECT_EQ(parse_ok("(3.0) can0 123##1").fd_flags, 0x01);  // BRS, no data
  EXPECT_EQ(parse_ok("(3.0) can0 123##2").fd_flags, 0x02);  // ESI
  EXPECT_EQ(parse_ok("(3.0) can0 123##3").fd_flags, 0x03);
  EXPECT_EQ(parse_ok("(3.0) can0 123##5").fd_flags, 0x01);  // FDF (4) is implied by fd

  std::string line = "(3.0) can0 1FFFFFFF##1";
  for (int i = 0; i < 64; ++i) line += (i % 2 != 0) ? "5A" : "A5";
  const CanFrame big = parse_ok(line);
  EXPECT_TRUE(big.fd && big.extended);
  ASSERT_EQ(big.len, 64);
  EXPECT_EQ(big.data[63], 0x5A);
  for (const int n : {12, 16, 20, 24, 32, 48}) {
    EXPECT_EQ(parse_ok("(3.0) can0 123##0" + std::string(static_cast<std::size_t>(2 * n), '1')).len, n);
  }
}

TEST(CandumpLineParse, ErrorFrame) {
  const CanFrame f = parse_ok("(4.0) can0 20000080#0000000000000011");
  EXPECT_TRUE(f.error);
  EXPECT_FALSE(f.extended);
  EXPECT_EQ(f.id, 0x80U);  // CAN_ERR_BUSERROR, flag stripped
  EXPECT_EQ(f.len, 8);
  EXPECT_EQ(f.data[7], 0x11);
  // python-can writes error frames without data.
  const CanFrame bare = parse_ok("(4.0) can0 20000080#");
  EXPECT_TRUE(bare.error);
  EXPECT_EQ(bare.len, 0);
}

TEST(CandumpLineParse, TimestampForms) {
  EXPECT_EQ(parse_ok("(166) vcan0 21A#FE").timestamp_us, 166000000);
  EXPECT_EQ(parse_ok("(166.000000) vcan0 21A#FE").timestamp_us, 166000000);
  EXPECT_EQ(parse_ok("(166.) vcan0 21A#FE").timestamp_us, 166000000);
  EXPECT_EQ(parse_ok("(166.5) vcan0 21A#FE").timestamp_us, 166500000);
  EXPECT_EQ(parse_ok("(0000000166.000042) vcan0 21A#FE").timestamp_us, 166000042);
  // Past the microsecond digits are truncated, never rounded up.
  EXPECT_EQ(parse_ok("(166.1234569999) vcan0 21A#FE").timestamp_us, 166123456);
}

TEST(CandumpLineParse, ToleratedDecorations) {
  const std::string base = "(7.25) can0 123#0102";
  const CanFrame ref = parse_ok(base);
  for (const std::string& line :
       {base + "\r", base + "\r\n", base + "  \t", base + " R", base + " T", base + " t\r\n",
       std::string("(7.25)   can0\t123#0102"), std::string("  (7.25) can0 123#0102"),
       std::string("(7.25) can0 123#01.02")}) {
    const CanFrame f = parse_ok(line);
    EXPECT_EQ(f.id, ref.id) << line;
    EXPECT_EQ(f.len, ref.len) << line;
    EXPECT_EQ(f.data, ref.data) << line;
    EXPECT_EQ(f.timestamp_us, ref.timestamp_us) << line;
    EXPECT_EQ(f.iface_name(), "can0") << line;
  }
  // len8_dlc: raw DLC 9..F after 8 bytes; data kept.
  EXPECT_EQ(parse_ok("(1.0) can0 123#1122334455667788_E").len, 8);
}

struct BadLine {
  std::string line;
  LogLineError kind;
  std::string at;        // the offending text; the column is where it starts
  std::string expected;  // a phrase the message must contain
};

// Column = 1 + offset of `at` in the line (rfind: the offending text is the last match).
std::size_t column_of(const BadLine& b) {
  if (b.at.empty()) return b.line.size() + 1;  // "found end of line"
  return b.line.rfind(b.at) + 1;
}

class CandumpLineErrors : public ::testing::TestWithParam<BadLine> {};

TEST_P(CandumpLineErrors, ReportsKindColumnAndMessage) {
  const BadLine& b = GetParam();
  CanFrame f;
  const auto problem = parse_candump_line(b.line, f);
  ASSERT_TRUE(problem.has_value()) << b.line;
  EXPECT_EQ(to_string(problem->kind), to_string(b.kind)) << b.line << " -> " << problem->message;
  EXPECT_EQ(problem->column, column_of(b)) << b.line << " -> " << problem->message;
  EXPECT_NE(problem->message.find(b.expected), std::string::npos)
      << b.line << " -> message '" << problem->message << "' lacks '" << b.expected << "'";
}

INSTANTIATE_TEST_SUITE_P(
    EveryKind, CandumpLineErrors,
    ::testing::Values(
        BadLine{"can0 123#00", LogLineError::kMissingTimestamp, "can0", "expected '(' opening the timestamp, found 'c'"},
        BadLine{"1.0) can0 123#00", LogLineError::kMissingTimestamp, "1.0)", "found '1'"},
        BadLine{"(1.0x) can0 123#00", LogLineError::kBadTimestamp, "x)", "found 'x'"},
        BadLine{"(-1.0) can0 123#00", LogLineError::kBadTimestamp, "-1", "not negative"},
        BadLine{"() can0 123#00", LogLineError::kBadTimestamp, ")", "seconds"},
        BadLine{"(1.0 can0 123#00", LogLineError::kBadTimestamp, " can0", "closing ')'"},
        BadLine{"(99999999999999999999.0) can0 123#00", LogLineError::kBadTimestamp, "99999999999999999999.0",
                "too large"},
        BadLine{"(1.0)", LogLineError::kMissingInterface, "", "found end of line"},
        BadLine{"(1.0)can0 123#00", LogLineError::kMissingInterface, "can0", "expected a space"},
        BadLine{"(1.0) 123#00", LogLineError::kMissingInterface, "123#00", "found the frame '123#00'"},
        BadLine{"(1.0) averyveryverylongname 123#00", LogLineError::kMissingInterface, "avery", "at most 15"},
        BadLine{"(1.0) can0", LogLineError::kMissingFrame, "", "after interface 'can0'"},
        BadLine{"(1.0) can0 1234#00", LogLineError::kBadId, "1234#", "has 4 hex digits"},
        BadLine{"(1.0) can0 #00", LogLineError::kBadId, "#00", "has 0 hex digits"},
        BadLine{"(1.0) can0 12G#00", LogLineError::kBadId, "G#", "found 'G'"},
        BadLine{"(1.0) can0 800#00", LogLineError::kBadId, "800", "above 0x7FF"},
        BadLine{"(1.0) can0 40000000#00", LogLineError::kBadId, "4000", "above 0x1FFFFFFF"},
        BadLine{"(1.0) can0 A0000080#00", LogLineError::kBadId, "A000", "EFF or RTR flag"},
        BadLine{"(1.0) can0 123:00", LogLineError::kBadSeparator, ":00", "expected '#' after the CAN id"},
        BadLine{"(1.0) can0 123", LogLineError::kBadSeparator, "", "found end of frame"},
        BadLine{"(1.0) can0 123#00 junk", LogLineError::kBadSeparator, "junk", "direction flag R/T"},
        BadLine{"(1.0) can0 20000080##000", LogLineError::kBadSeparator, "#000", "error frames are classic"},
        BadLine{"(1.0) can0 123#DEADBXEF", LogLineError::kBadHex, "XEF", "found 'X'"},
        BadLine{"(1.0) can0 123#00#11", LogLineError::kBadHex, "#11", "found '#'"},
        BadLine{"(1.0) can0 123#R5x", LogLineError::kBadHex, "x", "after the remote request"},
        BadLine{"(1.0) can0 20000080#R", LogLineError::kBadHex, "R", "never remote requests"},
        BadLine{"(1.0) can0 123#11_E", LogLineError::kBadHex, "_E", "exactly 8 classic"},
        BadLine{"(1.0) can0 123#ABC", LogLineError::kOddNibbles, "C", "odd number of hex digits (3)"},
        BadLine{"(1.0) can0 123#A.BC", LogLineError::kOddNibbles, "A.", "one hex digit"},
        BadLine{"(1.0) can0 123#112233445566778899", LogLineError::kTooLong, "1122", "9 data bytes, at most 8"},
        BadLine{"(1.0) can0 123#R9", LogLineError::kTooLong, "9", "above 8"},
        BadLine{"(1.0) can0 123##0" + std::string(20, 'A'), LogLineError::kTooLong, std::string(20, 'A'),
                "not a valid FD length"},
        BadLine{"(1.0) can0 123##0" + std::string(130, 'A'), LogLineError::kTooLong, std::string(130, 'A'),
                "65 data bytes, at most 64"},
        BadLine{"(1.0) can0 123##", LogLineError::kBadFdFlags, "", "found end of frame"},
        BadLine{"(1.0) can0 123##8AA", LogLineError::kBadFdFlags, "8AA", "flags nibble 0-7"},
        BadLine{"(1.0) can0 123##GAA", LogLineError::kBadFdFlags, "GAA", "found 'G'"},
        BadLine{"(1.0) can0 123#" + std::string(5000, '0'), LogLineError::kLineTooLong,
                std::string(5000 + 15 - kMaxCandumpLineLength, '0'), "5015 bytes long"}));

TEST(CandumpLineParse, CounterNamesAreStableAndDistinct) {
  std::set<std::string_view> names;
  for (const LogLineError e : kAllLogLineErrors) names.insert(to_string(e));
  EXPECT_EQ(names.size(), kLogLineErrorCount);
  EXPECT_EQ(to_string(LogLineError::kBadHex), "bad_hex");
  EXPECT_EQ(to_string(LogLineError::kOddNibbles), "odd_nibbles");
  EXPECT_EQ(to_string(LogLineError::kTooLong), "dlc_too_long");
  EXPECT_EQ(to_string(LogLineError::kLineTooLong), "line_too_long");
  EXPECT_EQ(to_string(LogLineError::kMissingTimestamp), "missing_timestamp");
}

TEST(CandumpLineParse, GarbageNeverCrashes) {
  // Every prefix and every single-byte corruption of a valid FD line must
  // either parse or yield a problem with a column inside (or just past) the line.
  const std::string good = "(1699999999.123456) can0 1ABCDEF0##3" + std::string(24, 'F') + " R";
  for (std::size_t n = 0; n <= good.size(); ++n) {
    CanFrame f;
    const std::string prefix = good.substr(0, n);
    if (const auto p = parse_candump_line(prefix, f)) {
      EXPECT_GE(p->column, 1U);
      EXPECT_LE(p->column, prefix.size() + 1);
      EXPECT_FALSE(p->message.empty());
    }
  }
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const char c : {'\0', '\xff', '#', '(', ' ', 'Z', '.', '_'}) {
      std::string bad = good;
      bad[i] = c;
      CanFrame f;
      if (const auto p = parse_candump_line(bad, f)) {
        EXPECT_LE(p->column, bad.size() + 1) << bad;
      }
    }
  }
}

}  // namespace
}  // namespace resolver
