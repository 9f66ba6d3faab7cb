// Interop with can-utils: log2asc (the same parse_canframe() canplayer uses)
// converts our writer's log to Vector ASC, frame for frame.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/candump/candump_writer.h"
#include "tests/unit/candump/candump_test_support.h"

namespace resolver {
namespace {

using candump_test::TempPath;

constexpr const char* kLog2Asc = "/usr/bin/log2asc";

std::string hex_byte(std::uint8_t b) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  return {kDigits[b >> 4U], kDigits[b & 0xFU]};
}

std::string asc_id(const CanFrame& f) {
  std::ostringstream s;
  s << std::uppercase << std::hex << f.id << (f.extended ? "x" : "");
  return s.str();
}

std::vector<std::string> tokens(const std::string& line) {
  std::istringstream s(line);
  std::vector<std::string> out;
  for (std::string t; s >> t;) out.push_back(t);
  return out;
}

// [us] "12.345678" -> 12345678, without floating point.
std::int64_t asc_time_us(const std::string& t) {
  const auto dot = t.find('.');
  return std::stoll(t.substr(0, dot)) * 1'000'000 + std::stoll(t.substr(dot + 1));
}

TEST(CandumpCanUtils, Log2AscReadsEveryFrameOfOurLog) {
  if (::access(kLog2Asc, X_OK) != 0) GTEST_SKIP() << kLog2Asc << " not installed (apt-get install can-utils)";
  std::mt19937_64 rng(5);
  std::int64_t t = 1'700'000'000'000'000;
  std::vector<CanFrame> frames;
  for (int i = 0; i < 2000; ++i) {
    CanFrame f = candump_test::random_frame(rng, t);
    f.set_iface("can0");  // log2asc maps interfaces given on its command line only
    frames.push_back(f);
  }
  TempPath log;
  TempPath asc(".asc");
  {
    CandumpWriter writer(log.str());
    for (const CanFrame& f : frames) writer.write(f);
    writer.close();
  }
  const std::string cmd = std::string(kLog2Asc) + " -I " + log.str() + " -O " + asc.str() + " can0";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  std::istringstream text(candump_test::read_text(asc.str()));
  std::vector<std::vector<std::string>> events;
  for (std::string line; std::getline(text, line);) {
    if (!line.empty() && line[0] == ' ') events.push_back(tokens(line));  // event lines are indented
  }
  ASSERT_EQ(events.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const CanFrame& f = frames[i];
    const auto& e = events[i];
    SCOPED_TRACE("frame " + std::to_string(i) + ": " + candump_test::describe(f));
    ASSERT_GE(e.size(), 3U);
    EXPECT_EQ(asc_time_us(e[0]), f.timestamp_us - frames[0].timestamp_us);
    std::vector<std::string> want_bytes;
    for (std::size_t k = 0; k < f.len; ++k) want_bytes.push_back(hex_byte(f.data[k]));
    if (f.error) {
      EXPECT_EQ(e[2], "ErrorFrame");
    } else if (f.fd) {
      // time CANFD channel Rx id [name] brs esi dlc len data...
      ASSERT_GE(e.size(), 9U + f.len);
      EXPECT_EQ(e[1], "CANFD");
      EXPECT_EQ(e[4], asc_id(f));
      const std::size_t len_at = 8;
      EXPECT_EQ(e[len_at - 3], std::to_string(f.fd_flags & 1U));         // BRS
      EXPECT_EQ(e[len_at - 2], std::to_string((f.fd_flags >> 1U) & 1U));  // ESI
      EXPECT_EQ(std::stoul(e[len_at]), f.len);
      EXPECT_EQ(std::vector<std::string>(e.begin() + len_at + 1, e.begin() + len_at + 1 + f.len), want_bytes);
    } else if (f.rtr) {
      EXPECT_EQ(e[2], asc_id(f));
      EXPECT_EQ(e[4], "r");
    } else {
      ASSERT_GE(e.size(), 6U + f.len);
      EXPECT_EQ(e[2], asc_id(f));
      EXPECT_EQ(e[4], "d");
      EXPECT_EQ(std::stoul(e[5]), f.len);
      EXPECT_EQ(std::vector<std::string>(e.begin() + 6, e.begin() + 6 + f.len), want_bytes);
    }
  }
}

}  // namespace
}  // namespace resolver
