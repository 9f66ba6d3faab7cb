// Vector ASC lines and files: every frame kind python-can's ASCWriter and
// CANoe write, the header's base and timestamp mode, and every bad line
// counted with its column, never fatal.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "drivers/asc/asc_line.h"
#include "drivers/asc/asc_reader.h"

namespace resolver {
namespace {

// 2023-11-14 22:13:20 UTC = 1700000000 s since the epoch.
constexpr std::int64_t kStartUs = 1'700'000'000'000'000;

struct Parsed {
  AscLineParser::Kind kind;
  CanFrame frame;
  TextProblem problem;
};

std::vector<Parsed> parse_all(const std::vector<std::string>& lines) {
  AscLineParser parser;
  std::vector<Parsed> out;
  for (const std::string& l : lines) {
    CanFrame f;
    const auto r = parser.parse(l, f);
    out.push_back(Parsed{r.kind, f, r.problem});
  }
  return out;
}

TEST(AscLine, WhatPythonCanWrites) {
  // python-can 4.1 ASCWriter output for five messages (frames from 1700000000.0005 s on).
  const auto out = parse_all({
      "date Tue Nov 24 07:15:09.079 AM 2026",
      "base hex  timestamps absolute",
      "internal events logged",
      "Begin Triggerblock Tue Nov 14 10:13:20.000 PM 2023",
      " 0.000000 Start of measurement",
      " 0.000000 1  100             Rx   d 8 00 01 02 03 04 05 06 07",
      " 0.000500 2  18FF0001x       Rx   d 2 0A 0B",
      " 0.001500 1  123             Rx   r 4 ",
      " 0.002500 1  ErrorFrame",
      " 0.003500 CANFD   1 Rx        200                                   1 0 9 12 00 01 02 03 04 05 06 07 08 09 0A 0B"
      "        0    0     3000        0        0        0        0        0",
      "End TriggerBlock",
  });
  ASSERT_EQ(out.size(), 11U);
  for (std::size_t i : {0, 1, 2, 3, 4, 10}) EXPECT_EQ(out[i].kind, AscLineParser::Kind::kNone) << i << out[i].problem.message;
  const CanFrame& a = out[5].frame;
  ASSERT_EQ(out[5].kind, AscLineParser::Kind::kFrame);
  EXPECT_EQ(a.id, 0x100U);
  EXPECT_FALSE(a.extended);
  EXPECT_EQ(a.len, 8);
  EXPECT_EQ(a.data[7], 7);
  EXPECT_EQ(a.timestamp_us, kStartUs);
  EXPECT_EQ(a.iface_name(), "can0");
  const CanFrame& b = out[6].frame;
  EXPECT_EQ(b.id, 0x18FF0001U);
  EXPECT_TRUE(b.extended);
  EXPECT_EQ(b.len, 2);
  EXPECT_EQ(b.data[1], 0x0B);
  EXPECT_EQ(b.timestamp_us, kStartUs + 500);
  EXPECT_EQ(b.iface_name(), "can1");
  EXPECT_TRUE(out[7].frame.rtr);
  EXPECT_EQ(out[7].frame.len, 4);
  EXPECT_TRUE(out[8].frame.error);
  const CanFrame& fd = out[9].frame;
  ASSERT_EQ(out[9].kind, AscLineParser::Kind::kFrame) << out[9].problem.message;
  EXPECT_TRUE(fd.fd);
  EXPECT_EQ(fd.fd_flags, 0x01);  // BRS
  EXPECT_EQ(fd.len, 12);
  EXPECT_EQ(fd.data[11], 0x0B);
  EXPECT_EQ(fd.timestamp_us, kStartUs + 3500);
}

// python-can 4.1 ASCWriter writes a message not flagged FD with more than 8 bytes as
// "d <byte count in hex>" and all its bytes (`d 40`), and remote frames as "r <DLC hex>";
// lines copied from its output (can.Message(..., is_fd=False), is_remote_frame=True).
TEST(AscLine, PythonCanLongClassicLinesAndRemoteFrames) {
  const auto out = parse_all({
      " 0.000000 1  100             Rx   d 40 00 01 02 03 04 05 06 07 08 09 0A 0B 0C 0D 0E 0F 10 11 12 13 14 15 16 17 18 19 1A 1B 1C 1D 1E 1F 20 21 22 23 24 25 26 27 28 29 2A 2B 2C 2D 2E 2F 30 31 32 33 34 35 36 37 38 39 3A 3B 3C 3D 3E 3F",
      " 0.000000 1  100             Rx   d 14 00 01 02 03 04 05 06 07 08 09 0A 0B 0C 0D 0E 0F 10 11 12 13",
      " 0.000000 1  100             Rx   d c 00 01 02 03 04 05 06 07 08 09 0A 0B",
      " 0.000000 1  100             Rx   d C 00 01 02 03 04 05 06 07  Length = 0 BitCount = 0 ID = 256",
      " 0.001000 1  100             Rx   r 8 ",
      " 0.002000 2  18FF0001x       Rx   r 0 ",
      " 0.100000 1  100             Rx   r c ",
      " 0.100000 1  100             Rx   r",
      " 0.000000 1  100             Rx   d 11 00 01 02 03 04 05 06 07 08 09 0A 0B 0C 0D 0E 0F 10 11 12 13",
      " 0.000000 1  100             Rx   d 40 00 01 02 03 04 05 06 07",
  });
  ASSERT_EQ(out[0].kind, AscLineParser::Kind::kFrame) << out[0].problem.message;
  EXPECT_EQ(out[0].frame.len, 64);
  EXPECT_TRUE(out[0].frame.fd);
  EXPECT_FALSE(out[0].frame.rtr);
  EXPECT_EQ(out[0].frame.data[63], 0x3F);
  ASSERT_EQ(out[1].kind, AscLineParser::Kind::kFrame) << out[1].problem.message;
  EXPECT_EQ(out[1].frame.len, 20);
  EXPECT_EQ(out[1].frame.data[19], 0x13);
  ASSERT_EQ(out[2].kind, AscLineParser::Kind::kFrame) << out[2].problem.message;
  EXPECT_EQ(out[2].frame.len, 12);
  EXPECT_TRUE(out[2].frame.fd);
  ASSERT_EQ(out[3].kind, AscLineParser::Kind::kFrame) << out[3].problem.message;
  EXPECT_EQ(out[3].frame.len, 8);  // CANoe's classic DLC code C: 8 bytes, then its trailing fields
  EXPECT_FALSE(out[3].frame.fd);
  for (std::size_t i : {4, 5, 6, 7}) {
    ASSERT_EQ(out[i].kind, AscLineParser::Kind::kFrame) << i << out[i].problem.message;
    EXPECT_TRUE(out[i].frame.rtr) << i;
    EXPECT_FALSE(out[i].frame.fd) << i;
  }
  EXPECT_EQ(out[4].frame.len, 8);
  EXPECT_EQ(out[5].frame.len, 0);
  EXPECT_TRUE(out[5].frame.extended);
  EXPECT_EQ(out[6].frame.len, 8);  // DLC C requests 8 bytes on classic CAN
  EXPECT_EQ(out[7].frame.len, 0);
  ASSERT_EQ(out[8].kind, AscLineParser::Kind::kProblem);  // 17 bytes: no CAN frame has that length
  EXPECT_EQ(out[8].problem.reason, "bad_dlc");
  EXPECT_EQ(out[8].problem.column, 37U);
  EXPECT_NE(out[8].problem.message.find("found '11'"), std::string::npos) << out[8].problem.message;
  ASSERT_EQ(out[9].kind, AscLineParser::Kind::kProblem);
  EXPECT_EQ(out[9].problem.reason, "missing_data");
  EXPECT_NE(out[9].problem.message.find("announces 64 data bytes, the line has 8"), std::string::npos)
      << out[9].problem.message;
}

TEST(AscLine, CanoeStyleLinesDecimalBaseAndRelativeTimes) {
  const auto out = parse_all({
      "base dec  timestamps relative",
      "   1.000000 1  256             Tx   d 2 10 255  Length = 0 BitCount = 0 ID = 256",
      "   0.250000 1  256             Rx   d 1 7",
      "   0.001000 CANFD   2 Rx 291 MyMessage 0 1 8 8 1 2 3 4 5 6 7 8   0 0 1000 0 0 0 0 0",
      "   0.001000 CANFD   2 Rx 291 0 0 3 3 1 2 3   0 0 0 0 0 0 0 0",  // EDL clear: a classic frame
  });
  ASSERT_EQ(out[1].kind, AscLineParser::Kind::kFrame) << out[1].problem.message;
  EXPECT_EQ(out[1].frame.id, 256U);
  EXPECT_EQ(out[1].frame.data[1], 255);
  EXPECT_EQ(out[1].frame.timestamp_us, 1'000'000);  // no date header: since the start
  EXPECT_EQ(out[2].frame.timestamp_us, 1'250'000);  // relative: since the previous event
  ASSERT_EQ(out[3].kind, AscLineParser::Kind::kFrame) << out[3].problem.message;
  EXPECT_EQ(out[3].frame.id, 291U);
  EXPECT_TRUE(out[3].frame.fd);
  EXPECT_EQ(out[3].frame.fd_flags, 0x02);  // ESI
  EXPECT_EQ(out[3].frame.data[7], 8);
  EXPECT_EQ(out[3].frame.iface_name(), "can1");
  EXPECT_EQ(out[3].frame.timestamp_us, 1'251'000);
  ASSERT_EQ(out[4].kind, AscLineParser::Kind::kFrame) << out[4].problem.message;
  EXPECT_FALSE(out[4].frame.fd);
  EXPECT_EQ(out[4].frame.len, 3);
}

TEST(AscLine, BadLinesNameReasonAndColumn) {
  struct Case {
    std::string line;
    std::string reason;
    std::size_t column;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {"0.00x1 1 100 Rx d 1 00", "bad_timestamp", 1, "0.001234"},
      {"0.001 1 800 Rx d 1 00", "bad_id", 9, "at most 0x7FF"},
      {"0.001 1 100 Rx d 8 00 01", "missing_data", 25, "announces 8 data bytes, the line has 2"},
      {"0.001 1 100 Rx d 2 00 0G", "bad_data_byte", 23, "found '0G'"},
      {"0.001 1 100 Up d 1 00", "bad_direction", 13, "Rx or Tx"},
      {"0.001 1 100 Rx d X 00", "bad_dlc", 18, "DLC 0..F"},
      {"0.001 1 Statistic: D 0 R 0 XD 0 XR 0", "asc_unsupported_event", 9, "carries no CAN frame"},
      {"0.001 SV: 1 0 1 ::Var = 3", "asc_unsupported_event", 7, "carries no CAN frame"},
      {"0.001 1 100 TxRq d 1 00", "asc_unsupported_event", 13, "transmit request"},
      {"0.001 CANFD 1 Rx 100 1 0 8 9 00", "bad_fd_fields", 22, "data length"},
      {"hello world", "asc_unknown_line", 1, "not a Vector ASC line"},
      {"base oct", "asc_bad_header", 6, "base hex"},
  };
  for (const Case& c : cases) {
    AscLineParser parser;
    CanFrame f;
    const auto r = parser.parse(c.line, f);
    SCOPED_TRACE(c.line);
    ASSERT_EQ(r.kind, AscLineParser::Kind::kProblem);
    EXPECT_EQ(r.problem.reason, c.reason);
    EXPECT_EQ(r.problem.column, c.column);
    EXPECT_NE(r.problem.message.find(c.fragment), std::string::npos) << r.problem.message;
  }
}

TEST(AscLine, DateHeaderReadsEnglishAndGermanMonthsIn12And24Hours) {
  EXPECT_EQ(parse_asc_date("Tue Nov 14 10:13:20.000 PM 2023"), kStartUs);
  EXPECT_EQ(parse_asc_date("Di Nov 14 22:13:20.5 2023"), kStartUs + 500'000);
  EXPECT_EQ(parse_asc_date("Mi Dez 31 00:00:00 2025"), 1'767'139'200'000'000);
  EXPECT_EQ(parse_asc_date("Sun Jan 1 12:00:00 am 2023"), 1'672'531'200'000'000);  // 12 am is midnight
  EXPECT_FALSE(parse_asc_date("yesterday"));
  EXPECT_FALSE(parse_asc_date("Nov 14 25:00:00 2023"));
}

TEST(AscReader, AFileWithBadLinesCarriesOn) {
  const std::string path = std::string(RESOLVER_BINARY_DIR) + "/asc_reader_test_" + std::to_string(::getpid()) + ".asc";
  std::ofstream(path) << "date Tue Nov 14 10:13:20.000 PM 2023\nbase hex  timestamps absolute\n"
                         "Begin Triggerblock\n"
                         "   0.000500 1  100  Rx  d 1 01\n"
                         "   garbage\n"
                         "   0.001000 1  101  Rx  d 1 02\n"
                         "End TriggerBlock\n";
  AscReader reader(path);
  CanFrame f;
  ASSERT_EQ(reader.next(f), AscReader::Status::kFrame);
  EXPECT_EQ(f.timestamp_us, kStartUs + 500);
  EXPECT_EQ(reader.line_number(), 4U);
  ASSERT_EQ(reader.next(f), AscReader::Status::kBadLine);
  EXPECT_EQ(reader.problem().reason, "asc_unknown_line");
  EXPECT_EQ(reader.problem().column, 4U);
  ASSERT_EQ(reader.next(f), AscReader::Status::kFrame);
  EXPECT_EQ(f.id, 0x101U);
  EXPECT_EQ(reader.next(f), AscReader::Status::kEnd);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace resolver
