// A user's own layout: DBC units honoured (degrees, turns, mA; a unit the
// program cannot know is an error naming the signal), layouts without a
// counter joined by message order, and the sample stream that turns either
// into resolver::Sample on one clock.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/frame_intake.h"
#include "daemon/decode/sample_stream.h"
#include "daemon/decode/signal_units.h"

namespace resolver {
namespace {

std::shared_ptr<const dbc::Database> parse(const std::string& text) {
  return std::make_shared<const dbc::Database>(dbc::parse_dbc(text, "test.dbc"));  // a failure throws, naming the line
}

// A scope export converted to CAN: two angles in degrees (0.01 deg per bit), no counter, no CRC.
std::string angle_dbc(const std::string& rd_unit, const std::string& ref_unit, bool two_messages = false) {
  std::string text = "VERSION \"\"\nBU_: SCOPE\nBO_ 291 SCOPE_ANGLES: 8 SCOPE\n"
                     " SG_ Resolver : 0|16@1+ (0.01,0) [0|360] \"" + rd_unit + "\" Vector__XXX\n";
  if (two_messages) text += "BO_ 292 SCOPE_REF: 8 SCOPE\n";
  text += " SG_ Encoder : " + std::string(two_messages ? "0" : "16") + "|16@1+ (0.01,0) [0|360] \"" + ref_unit +
          "\" Vector__XXX\n";
  return text;
}

SignalMap angle_map(bool two_messages = false) {
  SignalMap m;
  m.roles[static_cast<std::size_t>(Role::kRdAngle)] = SignalRef{"SCOPE_ANGLES", "Resolver"};
  m.roles[static_cast<std::size_t>(Role::kRefAngle)] = SignalRef{two_messages ? "SCOPE_REF" : "SCOPE_ANGLES", "Encoder"};
  m.counter_signal = "";
  m.crc = CrcAlgorithm::kNone;
  m.bench_info_message = "";
  return m;
}

CanFrame frame(std::uint32_t id, std::int64_t t_us, std::uint16_t a, std::uint16_t b = 0) {
  CanFrame f;
  f.id = id;
  f.len = 8;
  f.timestamp_us = t_us;
  f.data[0] = static_cast<std::uint8_t>(a & 0xFFU);
  f.data[1] = static_cast<std::uint8_t>(a >> 8U);
  f.data[2] = static_cast<std::uint8_t>(b & 0xFFU);
  f.data[3] = static_cast<std::uint8_t>(b >> 8U);
  return f;
}

std::string decoder_error(const std::string& dbc_text, const SignalMap& map) {
  try {
    FrameDecoder d(parse(dbc_text), map);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SignalUnits, AngleAndCurrentUnits) {
  EXPECT_DOUBLE_EQ(*angle_unit_to_rad("rad"), 1.0);
  EXPECT_DOUBLE_EQ(*angle_unit_to_rad("deg"), kPi / 180.0);
  EXPECT_DOUBLE_EQ(*angle_unit_to_rad(" Degree "), kPi / 180.0);
  EXPECT_DOUBLE_EQ(*angle_unit_to_rad("\xC2\xB0"), kPi / 180.0);  // UTF-8 degree sign
  EXPECT_DOUBLE_EQ(*angle_unit_to_rad("\xB0"), kPi / 180.0);      // Latin-1 degree sign
  EXPECT_DOUBLE_EQ(*angle_unit_to_rad("rev"), kTwoPi);
  EXPECT_DOUBLE_EQ(*angle_unit_to_rad("turn"), kTwoPi);
  EXPECT_FALSE(angle_unit_to_rad(""));
  EXPECT_FALSE(angle_unit_to_rad("grad"));
  EXPECT_DOUBLE_EQ(*current_unit_to_amps("A"), 1.0);
  EXPECT_DOUBLE_EQ(*current_unit_to_amps("mA"), 1e-3);
  EXPECT_FALSE(current_unit_to_amps("MA"));
  EXPECT_FALSE(current_unit_to_amps(""));
  EXPECT_EQ(quote_unit("\xB0"), "\"\\xB0\"");
  EXPECT_EQ(quote_unit("\xC2\xB0"), "\"\xC2\xB0\"");
}

TEST(FrameDecoderUnits, DegreesBecomeRadiansWrapped) {
  // Both spellings of the degree sign a DBC carries: UTF-8 and Latin-1.
  for (const std::string& ref_unit : {std::string("\xC2\xB0"), std::string("\xB0"), std::string("deg")}) {
    FrameDecoder d(parse(angle_dbc("deg", ref_unit)), angle_map());
    EXPECT_FALSE(d.has_counter());
    DecodedPart part;
    BenchInfo info;
    // 90.00 deg and 359.99 deg.
    ASSERT_EQ(d.decode(frame(291, 1, 9000, 35999), part, info).status, DecodeStatus::kPart);
    EXPECT_FALSE(part.has_counter);
    EXPECT_NEAR(part.values[static_cast<std::size_t>(Role::kRdAngle)], kPi / 2.0, 1e-12);
    EXPECT_NEAR(part.values[static_cast<std::size_t>(Role::kRefAngle)], 359.99 * kPi / 180.0, 1e-12);
  }
  // Turns: 0.01 rev per bit, 150 bits = 1.5 rev wraps to half a turn.
  FrameDecoder turns(parse(angle_dbc("rev", "rev")), angle_map());
  DecodedPart part;
  BenchInfo info;
  ASSERT_EQ(turns.decode(frame(291, 1, 150, 25), part, info).status, DecodeStatus::kPart);
  EXPECT_NEAR(part.values[static_cast<std::size_t>(Role::kRdAngle)], kPi, 1e-12);
  EXPECT_NEAR(part.values[static_cast<std::size_t>(Role::kRefAngle)], kPi / 2.0, 1e-12);
}

TEST(FrameDecoderUnits, UnknownOrMissingAngleUnitIsAnErrorNamingTheSignal) {
  const std::string grad = decoder_error(angle_dbc("grad", "deg"), angle_map());
  EXPECT_NE(grad.find("SCOPE_ANGLES.Resolver"), std::string::npos) << grad;
  EXPECT_NE(grad.find("\"grad\""), std::string::npos) << grad;
  EXPECT_NE(grad.find("rad, deg"), std::string::npos) << grad;
  const std::string none = decoder_error(angle_dbc("deg", ""), angle_map());
  EXPECT_NE(none.find("SCOPE_ANGLES.Encoder"), std::string::npos) << none;
  EXPECT_NE(none.find("has no unit"), std::string::npos) << none;
}

TEST(FrameDecoderUnits, MilliampsBecomeAmps) {
  const std::string dbc = "VERSION \"\"\nBU_: X\nBO_ 16 CUR: 8 X\n"
                          " SG_ Ia : 0|16@1- (1,0) [-32768|32767] \"mA\" Vector__XXX\n"
                          " SG_ Ib : 16|16@1- (1,0) [-32768|32767] \"mA\" Vector__XXX\n"
                          " SG_ Ic : 32|16@1- (1,0) [-32768|32767] \"kA\" Vector__XXX\n"
                          " SG_ th : 48|16@1+ (1,0) [0|65535] \"rad\" Vector__XXX\n";
  SignalMap m;
  m.roles[static_cast<std::size_t>(Role::kIA)] = SignalRef{"CUR", "Ia"};
  m.roles[static_cast<std::size_t>(Role::kIB)] = SignalRef{"CUR", "Ib"};
  m.roles[static_cast<std::size_t>(Role::kRdAngle)] = SignalRef{"CUR", "th"};
  m.counter_signal = "";
  m.crc = CrcAlgorithm::kNone;
  m.bench_info_message = "";
  FrameDecoder d(parse(dbc), m);
  DecodedPart part;
  BenchInfo info;
  ASSERT_EQ(d.decode(frame(16, 1, 1500, static_cast<std::uint16_t>(-250)), part, info).status, DecodeStatus::kPart);
  EXPECT_NEAR(part.values[static_cast<std::size_t>(Role::kIA)], 1.5, 1e-12);
  EXPECT_NEAR(part.values[static_cast<std::size_t>(Role::kIB)], -0.25, 1e-12);
  m.roles[static_cast<std::size_t>(Role::kIC)] = SignalRef{"CUR", "Ic"};
  const std::string ka = decoder_error(dbc, m);
  EXPECT_NE(ka.find("CUR.Ic"), std::string::npos) << ka;
  EXPECT_NE(ka.find("A, mA"), std::string::npos) << ka;
}

TEST(FrameDecoderUnits, TheBundledLayoutDescribesItself) {
  auto db = std::make_shared<const dbc::Database>(dbc::load_dbc_file(RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc"));
  FrameDecoder d(db, SignalMap::bench_default());
  EXPECT_EQ(d.describe_layout(),
            "RESOLVER_SAMPLE 0x100 (sin = sin, cos = cos, rd_angle = rd_angle), PHASE_CURRENTS 0x101 (i_a = i_a, "
            "i_b = i_b, i_c = i_c), REFERENCE_ANGLE 0x102 (ref_angle = ref_angle), counter 'counter'");
  FrameDecoder scope(parse(angle_dbc("deg", "deg")), angle_map());
  EXPECT_EQ(scope.describe_layout(), "SCOPE_ANGLES 0x123 (rd_angle = Resolver, ref_angle = Encoder), no counter");
}

struct Collected {
  std::vector<Sample> samples;
  std::vector<std::string> problems;
  SampleStream::Callbacks callbacks() {
    return {[this](const Sample& s, std::uint8_t) { samples.push_back(s); }, nullptr,
            [this](std::string_view r, const std::string& m) { problems.push_back(std::string(r) + ": " + m); }};
  }
};

SampleStreamConfig stream_config(double rate_hz) {
  SampleStreamConfig c;
  c.clock.sample_rate_hz = rate_hz;
  return c;
}

TEST(LayoutWithoutCounter, OneMessagePerSampleAtAHundredHertz) {
  Collected got;
  SampleStream stream(std::make_shared<const FrameDecoder>(parse(angle_dbc("deg", "deg")), angle_map()),
                      stream_config(100.0), got.callbacks());
  constexpr std::int64_t kT0 = 1'700'000'000'000'000;
  for (int k = 0; k < 100; ++k) {
    if (k == 50 || k == 51) continue;  // two samples lost: found from time
    stream.feed(frame(291, kT0 + 10'000LL * k, static_cast<std::uint16_t>(100 * k), static_cast<std::uint16_t>(99 * k)));
  }
  stream.flush();
  ASSERT_EQ(got.samples.size(), 98U);
  EXPECT_EQ(stream.intake().stats().samples_complete, 98);
  EXPECT_EQ(stream.intake().rejects().get("sample_gap"), 1);
  EXPECT_EQ(stream.intake().rejects().get("samples_lost"), 2);
  for (const Sample& s : got.samples) {
    EXPECT_TRUE(s.has_rd && s.has_ref);
    EXPECT_NEAR(s.t, static_cast<double>(s.index) * 0.01, 1e-9);
    EXPECT_NEAR(s.theta_rd, wrap_2pi(static_cast<double>(s.index) * kPi / 180.0), 1e-9);
  }
  EXPECT_EQ(got.samples[50].index, 52);
}

TEST(LayoutWithoutCounter, TwoMessagesJoinFromTheLeadingOneEvenWhenTheLogStartsMidPeriod) {
  Collected got;
  SampleStream stream(std::make_shared<const FrameDecoder>(parse(angle_dbc("deg", "deg", true)), angle_map(true)),
                      stream_config(0.0), got.callbacks());
  constexpr std::int64_t kT0 = 1'700'000'000'000'000;
  // The log starts with the second message of period 0; each period: SCOPE_ANGLES then 20 us later SCOPE_REF.
  stream.feed(frame(292, kT0 + 20, 0));
  for (int k = 1; k < 60; ++k) {
    const std::int64_t t = kT0 + 10'000LL * k;
    if (k != 30) stream.feed(frame(291, t, static_cast<std::uint16_t>(100 * k)));  // period 30 lost its leading frame
    stream.feed(frame(292, t + 20, static_cast<std::uint16_t>(100 * k)));
  }
  stream.flush();
  // Period 0 (ref only) and period 30 (ref only) are incomplete; every other
  // sample joins the two messages of one period: the same angle in both.
  EXPECT_EQ(stream.intake().stats().samples_incomplete, 2);
  EXPECT_EQ(stream.intake().stats().samples_complete, 58);
  for (const Sample& s : got.samples) {
    if (s.has_rd && s.has_ref) {
      EXPECT_NEAR(s.theta_rd, s.theta_m_ref, 1e-12) << s.index;
    }
  }
}

TEST(SampleStream, ToSampleKeepsOnlyCompleteSignalGroups) {
  BenchSample b;
  b.timestamp_us = 123;
  b.roles = role_bit(Role::kSin) | role_bit(Role::kIA) | role_bit(Role::kIB) | role_bit(Role::kRdAngle);
  b.values[static_cast<std::size_t>(Role::kRdAngle)] = 1.25;
  ClockReading r;
  r.t = 0.5;
  r.index = 7;
  const Sample s = to_sample(b, r);
  EXPECT_EQ(s.t, 0.5);
  EXPECT_EQ(s.index, 7);
  EXPECT_EQ(s.utime, 123);
  EXPECT_TRUE(s.has_rd);
  EXPECT_EQ(s.theta_rd, 1.25);
  EXPECT_FALSE(s.has_sincos);    // cos missing
  EXPECT_FALSE(s.has_currents);  // i_c missing
  EXPECT_FALSE(s.has_ref);
}

TEST(SampleStream, SliceKeepsTheClockAndDropsTheRest) {
  Collected got;
  SampleStreamConfig c = stream_config(100.0);
  c.slice.from_s = 0.2;
  c.slice.to_s = 0.5;
  SampleStream stream(std::make_shared<const FrameDecoder>(parse(angle_dbc("deg", "deg")), angle_map()), c,
                      got.callbacks());
  for (int k = 0; k < 100 && !stream.past_slice_end(); ++k) stream.feed(frame(291, 10'000LL * k, 0));
  ASSERT_EQ(got.samples.size(), 31U);  // 0.20, 0.21, ..., 0.50 s
  EXPECT_NEAR(got.samples.front().t, 0.2, 1e-9);
  EXPECT_NEAR(got.samples.back().t, 0.5, 1e-9);
  EXPECT_TRUE(stream.past_slice_end());
  EXPECT_EQ(stream.samples_outside_slice(), 21);  // 20 before, the first one after
}

TEST(SampleStream, RowsWithoutTimeRunOnTheRowRate) {
  Collected got;
  SampleStreamConfig c;
  c.row_rate_hz = 50.0;
  SampleStream stream(std::make_shared<const FrameDecoder>(parse(angle_dbc("deg", "deg")), angle_map()), c,
                      got.callbacks());
  for (int k = 0; k < 10; ++k) {
    if (k == 4) continue;  // a bad row: its number is skipped, the time stays right
    RowSample row;
    row.sequence = k;
    row.roles = role_bit(Role::kRdAngle);
    row.values[static_cast<std::size_t>(Role::kRdAngle)] = 0.1 * k;
    stream.feed_row(row, static_cast<std::uint64_t>(k + 2));
  }
  ASSERT_EQ(got.samples.size(), 9U);
  EXPECT_EQ(stream.intake().stats().frames_seen, 9);
  EXPECT_EQ(stream.intake().stats().samples_complete, 9);
  EXPECT_NEAR(got.samples[4].t, 5.0 / 50.0, 1e-12);
  EXPECT_EQ(got.samples[4].index, 5);
  EXPECT_TRUE(got.problems.empty());
}

TEST(SampleStream, RowTimeThatGoesBackIsCountedWithItsLine) {
  Collected got;
  SampleStream stream(std::make_shared<const FrameDecoder>(parse(angle_dbc("deg", "deg")), angle_map()),
                      stream_config(0.0), got.callbacks());
  for (int k = 0; k < 20; ++k) {
    RowSample row;
    row.has_time = true;
    row.time_us = (k < 10 ? k : k - 15) * 10'000LL;  // steps back 150 ms at row 10
    row.sequence = k;
    row.roles = role_bit(Role::kRdAngle);
    stream.feed_row(row, static_cast<std::uint64_t>(k + 6));
  }
  stream.flush();  // the last rows wait in the reorder window until the end
  ASSERT_EQ(got.samples.size(), 20U);
  for (std::size_t i = 1; i < got.samples.size(); ++i) EXPECT_GT(got.samples[i].t, got.samples[i - 1].t) << i;
  ASSERT_EQ(got.problems.size(), 1U);
  EXPECT_NE(got.problems[0].find("timestamp_step_back: line 16: sample 10"), std::string::npos) << got.problems[0];
}

TEST(SampleStream, TwoSwappedRowsAreReorderedNotLost) {
  // Issue 25 ("Trust"): rows 10 and 11 of an export in the wrong time order were
  // read as a step back and two gaps: "samples_lost=2" of nothing missing.
  Collected got;
  SampleStream stream(std::make_shared<const FrameDecoder>(parse(angle_dbc("deg", "deg")), angle_map()),
                      stream_config(0.0), got.callbacks());
  for (int k = 0; k < 30; ++k) {
    const int when = k == 10 ? 11 : k == 11 ? 10 : k;
    RowSample row;
    row.has_time = true;
    row.time_us = when * 10'000LL;
    row.sequence = k;
    row.roles = role_bit(Role::kRdAngle);
    row.values[static_cast<std::size_t>(Role::kRdAngle)] = 0.01 * when;
    stream.feed_row(row, static_cast<std::uint64_t>(k + 6));
  }
  stream.flush();
  ASSERT_EQ(got.samples.size(), 30U);
  for (std::size_t i = 0; i < got.samples.size(); ++i) {
    EXPECT_EQ(got.samples[i].index, static_cast<std::int64_t>(i));
    EXPECT_NEAR(got.samples[i].t, 0.01 * static_cast<double>(i), 1e-9);
    EXPECT_NEAR(got.samples[i].theta_rd, 0.01 * static_cast<double>(i), 1e-12) << "in time order";
  }
  EXPECT_EQ(stream.intake().rejects().all().size(), 1U);
  EXPECT_EQ(stream.intake().rejects().get("rows_reordered"), 1);
  ASSERT_EQ(got.problems.size(), 1U);
  EXPECT_NE(got.problems[0].find("rows_reordered: line 17: row at (0.100000) comes before line 16's (0.110000) in "
                                 "time: rows out of order, used in time order (not lost)"),
            std::string::npos)
      << got.problems[0];
}

}  // namespace
}  // namespace resolver
