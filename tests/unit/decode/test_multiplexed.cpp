// Multiplexed DBC messages (issue 25): a signal the decoder reads is taken
// only from frames whose multiplexor selects its page. A temperature page that
// shares the sin/cos bits is never decoded as sin/cos: its frames are rejected
// (mux_page_unmapped) or, when the page carries some roles, the others are
// absent from that frame (mux_role_absent). Extended multiplexing of a signal
// the decoder reads is refused naming the DBC line.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/frame_intake.h"

namespace resolver {
namespace {

// Line 3: the message; 4: counter; 5: the switch; 6..8: pages 0 and 1 over the same bytes 2..5; 9: rd.
const std::string kMuxDbc =
    "VERSION \"\"\nBU_: INV RD\nBO_ 256 FB: 8 INV\n"
    " SG_ counter : 0|8@1+ (1,0) [0|255] \"\" RD\n"
    " SG_ page M : 8|8@1+ (1,0) [0|3] \"\" RD\n"
    " SG_ s m0 : 16|16@1- (1,0) [-32768|32767] \"\" RD\n"
    " SG_ c m0 : 32|16@1- (1,0) [-32768|32767] \"\" RD\n"
    " SG_ temp m1 : 16|16@1- (0.1,0) [-40|150] \"degC\" RD\n"
    " SG_ rd : 48|16@1+ (0.0001,0) [0|6.3] \"rad\" RD\n";

std::shared_ptr<const dbc::Database> parse(const std::string& text) {
  try {
    return std::make_shared<const dbc::Database>(dbc::parse_dbc(text, "test.dbc"));
  } catch (const InputError& e) {
    ADD_FAILURE() << e.what();
    return std::make_shared<const dbc::Database>();
  }
}

SignalMap map(bool with_rd) {
  SignalMap m;
  m.roles[static_cast<std::size_t>(Role::kSin)] = SignalRef{"FB", "s"};
  m.roles[static_cast<std::size_t>(Role::kCos)] = SignalRef{"FB", "c"};
  if (with_rd) m.roles[static_cast<std::size_t>(Role::kRdAngle)] = SignalRef{"FB", "rd"};
  m.crc_signal = "";
  m.crc = CrcAlgorithm::kNone;
  m.bench_info_message = "";
  return m;
}

CanFrame frame(std::int64_t t_us, std::uint8_t counter, std::uint8_t page, std::int16_t a, std::int16_t b,
               std::uint16_t rd = 0) {
  CanFrame f;
  f.id = 256;
  f.len = 8;
  f.timestamp_us = t_us;
  const auto ua = static_cast<std::uint16_t>(a);
  const auto ub = static_cast<std::uint16_t>(b);
  f.data = {counter, page, static_cast<std::uint8_t>(ua & 0xFFU), static_cast<std::uint8_t>(ua >> 8U),
            static_cast<std::uint8_t>(ub & 0xFFU), static_cast<std::uint8_t>(ub >> 8U),
            static_cast<std::uint8_t>(rd & 0xFFU), static_cast<std::uint8_t>(rd >> 8U)};
  return f;
}

struct Recorder {
  std::vector<BenchSample> samples;
  std::vector<std::string> problems;
  FrameIntake::Callbacks callbacks() {
    return {[this](const BenchSample& s) { samples.push_back(s); }, [](const BenchInfo&) {},
            [this](std::string_view r, const std::string& m) { problems.push_back(std::string(r) + ": " + m); }};
  }
};

TEST(Multiplexed, TemperaturePageIsNeverDecodedAsSinCos) {
  Recorder rec;
  FrameIntake intake(std::make_shared<const FrameDecoder>(parse(kMuxDbc), map(false)), 8, rec.callbacks());
  // Each period: the temperature page first (25.0 degC = raw 250 in the sin bits), then sin/cos.
  for (int k = 1; k <= 10; ++k) {
    const auto c = static_cast<std::uint8_t>(k);
    intake.feed(frame(1000 * k, c, 1, 250, 0x7777), static_cast<std::uint64_t>(2 * k));
    intake.feed(frame(1000 * k + 1, c, 0, static_cast<std::int16_t>(100 * k), static_cast<std::int16_t>(-100 * k)));
  }
  intake.flush();
  ASSERT_EQ(rec.samples.size(), 10U);
  for (int k = 1; k <= 10; ++k) {
    const BenchSample& s = rec.samples[static_cast<std::size_t>(k - 1)];
    ASSERT_TRUE(s.has(Role::kSin) && s.has(Role::kCos)) << k;
    EXPECT_EQ(s.get(Role::kSin), 100.0 * k) << k;
    EXPECT_EQ(s.get(Role::kCos), -100.0 * k) << k;
  }
  EXPECT_EQ(intake.rejects().get("mux_page_unmapped"), 10);
  EXPECT_EQ(intake.rejects().get("duplicate_in_sample"), 0);
  EXPECT_EQ(intake.stats().frames_decoded, 10);
  ASSERT_FALSE(rec.problems.empty());
  EXPECT_NE(rec.problems[0].find("mux_page_unmapped: line 2: frame 100 at"), std::string::npos) << rec.problems[0];
  EXPECT_NE(rec.problems[0].find("FB multiplexor 'page' = 1 selects a page without what resolverd reads "
                                 "(sin on page 0, cos on page 0)"),
            std::string::npos)
      << rec.problems[0];
}

TEST(Multiplexed, RolesOffThePageAreAbsentAndCounted) {
  // rd is on every page; sin/cos only on page 0. One frame per period (the counter counts frames).
  Recorder rec;
  FrameIntake intake(std::make_shared<const FrameDecoder>(parse(kMuxDbc), map(true)), 8, rec.callbacks());
  for (int k = 1; k <= 6; ++k) {
    const auto page = static_cast<std::uint8_t>(k % 2);
    intake.feed(frame(1000 * k, static_cast<std::uint8_t>(k), page, 300, -300, static_cast<std::uint16_t>(1000 * k)));
  }
  intake.flush();
  ASSERT_EQ(rec.samples.size(), 6U);
  for (int k = 1; k <= 6; ++k) {
    const BenchSample& s = rec.samples[static_cast<std::size_t>(k - 1)];
    EXPECT_TRUE(s.has(Role::kRdAngle)) << k;
    EXPECT_NEAR(s.get(Role::kRdAngle), 0.1 * k, 1e-12) << k;
    EXPECT_EQ(s.has(Role::kSin), k % 2 == 0) << k;
    EXPECT_EQ(s.has(Role::kCos), k % 2 == 0) << k;
  }
  EXPECT_EQ(intake.rejects().get("mux_role_absent"), 6);  // sin and cos in 3 frames
  EXPECT_EQ(intake.rejects().get("mux_page_unmapped"), 0);
  ASSERT_FALSE(rec.problems.empty());
  EXPECT_NE(rec.problems[0].find("FB multiplexor page 1 does not carry sin, cos"), std::string::npos)
      << rec.problems[0];
}

std::string construction_error(const std::string& text, const SignalMap& m) {
  try {
    FrameDecoder d(parse(text), m);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Multiplexed, ExtendedMultiplexingOfASignalReadIsRefusedWithItsLine) {
  // Line 10: a second-level switch under page 1.
  const std::string nested = kMuxDbc + " SG_ sub m1M : 48|8@1+ (1,0) [0|0] \"\" RD\n";
  const std::string err = construction_error(nested, map(false));
  EXPECT_NE(err.find("test.dbc:10: message 'FB' uses extended multiplexing (signal 'sub' is a second-level "
                     "multiplexor (m1M)), which resolverd does not decode; role 'sin' reads 's'"),
            std::string::npos)
      << err;
  // SG_MUL_VAL_ ranges for 'c' (line 10): refused naming that line.
  const std::string ranged = kMuxDbc + "SG_MUL_VAL_ 256 c page 0-0, 2-3;\n";
  const std::string err2 = construction_error(ranged, map(false));
  EXPECT_NE(err2.find("test.dbc:10: message 'FB' uses extended multiplexing (SG_MUL_VAL_ makes signal 'c' present "
                      "for switch 'page' in 0-0,2-3)"),
            std::string::npos)
      << err2;
  EXPECT_NE(err2.find("role 'cos' reads 'c'"), std::string::npos) << err2;
  EXPECT_EQ(err2.find("role 'sin'"), std::string::npos) << err2;
  // Only plain signals read from a message with extended multiplexing: accepted.
  SignalMap plain;
  plain.roles[static_cast<std::size_t>(Role::kRdAngle)] = SignalRef{"FB", "rd"};
  plain.crc_signal = "";
  plain.crc = CrcAlgorithm::kNone;
  plain.bench_info_message = "";
  const std::string nested_elsewhere = kMuxDbc + " SG_ sub m1M : 40|8@1+ (1,0) [0|0] \"\" RD\n";
  EXPECT_EQ(construction_error(nested_elsewhere, plain), "");
}

}  // namespace
}  // namespace resolver
