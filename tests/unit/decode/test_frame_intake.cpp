// Frames of the default layout through the DBC-driven intake: decoding,
// joining, and every kind of bad frame counted without touching good samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/bench_layout.h"
#include "daemon/decode/frame_intake.h"

namespace resolver {
namespace {

std::shared_ptr<const FrameDecoder> bench_decoder() {
  auto loaded = dbc::load_dbc_file(RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc");
  EXPECT_TRUE(std::holds_alternative<dbc::Database>(loaded));
  auto db = std::make_shared<const dbc::Database>(std::get<dbc::Database>(std::move(loaded)));
  return std::make_shared<const FrameDecoder>(db, SignalMap::bench_default());
}

struct Recorder {
  std::vector<BenchSample> samples;
  std::vector<BenchInfo> infos;
  std::vector<std::string> problems;
  FrameIntake::Callbacks callbacks() {
    return {[this](const BenchSample& s) { samples.push_back(s); },
            [this](const BenchInfo& i) { infos.push_back(i); },
            [this](std::string_view r, const std::string& m) { problems.push_back(std::string(r) + ": " + m); }};
  }
};

// Sample k: counter k, sin = 100 k, cos = -100 k, rd = 1000 k, currents k mA, ref 10^6 k.
void push_sample(std::vector<CanFrame>& f, int k) {
  const auto c = static_cast<std::uint8_t>(k);
  const std::int64_t t = 1'000'000 + 500LL * k;
  f.push_back(bench::encode_resolver_sample(t, c, static_cast<std::int16_t>(100 * k), static_cast<std::int16_t>(-100 * k),
                                            static_cast<std::uint16_t>(1000 * k)));
  f.push_back(bench::encode_phase_currents(t + 1, c, static_cast<std::int16_t>(k), static_cast<std::int16_t>(-k), 0));
  f.push_back(bench::encode_reference_angle(t + 2, c, static_cast<std::uint32_t>(1'000'000U * static_cast<unsigned>(k))));
}

TEST(FrameIntake, DecodesAndJoinsTheDefaultLayout) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames;
  frames.push_back(bench::encode_bench_info(999'000, 3, 4, 12, 2000));
  for (int k = 1; k <= 10; ++k) push_sample(frames, k);
  for (const auto& f : frames) intake.feed(f);
  intake.flush();
  ASSERT_EQ(rec.infos.size(), 1U);
  EXPECT_EQ(rec.infos[0].p_r, 3);
  EXPECT_EQ(rec.infos[0].p, 4);
  EXPECT_EQ(rec.infos[0].rd_bits, 12);
  EXPECT_DOUBLE_EQ(rec.infos[0].sample_rate_hz, 2000.0);
  ASSERT_EQ(rec.samples.size(), 10U);
  for (int k = 1; k <= 10; ++k) {
    const BenchSample& s = rec.samples[static_cast<std::size_t>(k - 1)];
    EXPECT_EQ(s.counter, k);
    EXPECT_TRUE(s.complete());
    EXPECT_DOUBLE_EQ(s.get(Role::kSin), 100.0 * k);
    EXPECT_DOUBLE_EQ(s.get(Role::kCos), -100.0 * k);
    EXPECT_NEAR(s.get(Role::kRdAngle), 1000.0 * k * (2.0 * 3.141592653589793 / 65536.0), 1e-12);
    EXPECT_NEAR(s.get(Role::kIA), 1e-3 * k, 1e-12);
    EXPECT_NEAR(s.get(Role::kIB), -1e-3 * k, 1e-12);
  }
  EXPECT_EQ(intake.rejects().total(), 0);
  EXPECT_EQ(intake.stats().samples_incomplete, 0);
}

TEST(FrameIntake, BadFramesAreCountedAndNeverCorruptNeighbours) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames;
  for (int k = 1; k <= 4; ++k) push_sample(frames, k);
  // Corrupted copy of sample 5's resolver frame (bit flip): CRC must catch it.
  std::vector<CanFrame> s5;
  push_sample(s5, 5);
  CanFrame bad = s5[0];
  bad.data[2] ^= 0x10;
  frames.push_back(bad);
  frames.push_back(s5[1]);
  frames.push_back(s5[2]);
  // Wrong length, unknown ID, remote frame.
  CanFrame short_frame = s5[1];
  short_frame.len = 6;
  frames.push_back(short_frame);
  CanFrame unknown = s5[1];
  unknown.id = 0x321;
  frames.push_back(unknown);
  CanFrame rtr = s5[1];
  rtr.rtr = true;
  rtr.len = 0;
  frames.push_back(rtr);
  CanFrame err;
  err.error = true;
  err.id = 0x40;
  frames.push_back(err);
  push_sample(frames, 6);
  // Repeated frame of sample 6 (same counter): dropped, sample 6 intact.
  CanFrame dup = frames.back();
  frames.push_back(dup);
  // Gap: samples 7, 8 lost.
  push_sample(frames, 9);
  push_sample(frames, 10);
  for (const auto& f : frames) intake.feed(f);
  intake.flush();

  EXPECT_EQ(intake.rejects().get("crc"), 1);
  EXPECT_EQ(intake.rejects().get("wrong_dlc"), 1);
  EXPECT_EQ(intake.rejects().get("unknown_id"), 1);
  EXPECT_EQ(intake.rejects().get("remote_frame"), 1);
  EXPECT_EQ(intake.rejects().get("counter_repeated"), 1);
  EXPECT_EQ(intake.stats().bus_errors, 1);
  EXPECT_GE(intake.rejects().get("counter_gap"), 1);
  // Samples 7 and 8 (three frames each) plus the CRC-rejected resolver frame
  // of sample 5, which the RESOLVER_SAMPLE counter also sees missing (4 -> 6).
  EXPECT_EQ(intake.stats().frames_lost, 2 * 3 + 1);
  // Sample 5 lacks its resolver frame: emitted incomplete, without sin/cos/rd.
  const auto it5 = std::find_if(rec.samples.begin(), rec.samples.end(), [](const BenchSample& s) { return s.counter == 5; });
  ASSERT_NE(it5, rec.samples.end());
  EXPECT_FALSE(it5->complete());
  EXPECT_FALSE(it5->has(Role::kRdAngle));
  EXPECT_TRUE(it5->has(Role::kIA));
  // Every other sample is complete and holds its own values.
  for (const auto& s : rec.samples) {
    if (s.counter == 5) continue;
    EXPECT_TRUE(s.complete()) << "counter " << int(s.counter);
    EXPECT_DOUBLE_EQ(s.get(Role::kSin), 100.0 * s.counter);
  }
  // Index advances over the gap.
  EXPECT_EQ(rec.samples.back().index - rec.samples.front().index, 9);
  EXPECT_FALSE(rec.problems.empty());
  EXPECT_NE(rec.problems.front().find("frame 100"), std::string::npos) << rec.problems.front();
}

std::vector<CanFrame> periods(int first, int count) {
  std::vector<CanFrame> f;
  for (int k = first; k < first + count; ++k) push_sample(f, k);
  return f;
}

// Issue 25 ("Trust"): two benches (or two buses) in one candump log were joined
// into one stream; their unrelated counters read as 500 s of a standing rotor.
TEST(FrameIntake, OnlyTheFirstInterfaceWithABenchFrameIsRead) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames;
  CanFrame noise = bench::encode_phase_currents(999'000, 0, 0, 0, 0);
  noise.id = 0x321;  // another ECU on can1 first: not a frame of the layout, reads no interface yet
  noise.set_iface("can1");
  frames.push_back(noise);
  std::vector<CanFrame> a = periods(1, 40);
  std::vector<CanFrame> b = periods(101, 40);  // a second bench, its counter elsewhere
  for (std::size_t i = 0; i < a.size(); ++i) {
    a[i].set_iface("can0");
    b[i].set_iface("can1");
    b[i].timestamp_us = a[i].timestamp_us + 130;
    frames.push_back(a[i]);
    frames.push_back(b[i]);
  }
  for (const CanFrame& f : frames) intake.feed(f, 0);
  intake.flush();
  ASSERT_EQ(rec.samples.size(), 40U);
  for (std::size_t i = 0; i < rec.samples.size(); ++i) {
    EXPECT_EQ(rec.samples[i].index, static_cast<std::int64_t>(i) + 1);
    EXPECT_TRUE(rec.samples[i].complete());
  }
  EXPECT_EQ(intake.rejects().get("other_interface"), 120);
  EXPECT_EQ(intake.rejects().get("unknown_id"), 1);
  EXPECT_EQ(intake.rejects().total(), 121);
  ASSERT_EQ(intake.interfaces().size(), 2U);
  EXPECT_EQ(intake.interfaces()[0].name, "can1");
  EXPECT_EQ(intake.interfaces()[0].frames, 121);
  EXPECT_EQ(intake.interfaces()[0].left_out, 120);
  EXPECT_FALSE(intake.interfaces()[0].read);
  EXPECT_EQ(intake.interfaces()[1].name, "can0");
  EXPECT_TRUE(intake.interfaces()[1].read);
  const auto it = std::find_if(rec.problems.begin(), rec.problems.end(),
                               [](const std::string& p) { return p.rfind("other_interface", 0) == 0; });
  ASSERT_NE(it, rec.problems.end());
  EXPECT_NE(it->find("frame 100 at (1.000630) on can1: the log holds frames of more than one CAN interface; "
                     "only can0's are read"),
            std::string::npos)
      << *it;
  EXPECT_NE(it->find("grep ' can1 ' LOG > can1.log"), std::string::npos) << *it;
  EXPECT_EQ(intake.interface_note(),
            "the log holds frames of 2 CAN interfaces: can1 121 frames (120 left out: other_interface), can0 120 "
            "frames (read); one interface's frames make one sample stream. To read can1 instead, replay a log of "
            "its lines only (candump -l: grep ' can1 ' LOG > can1.log; a Vector ASC log: the lines of channel 2)");
}

TEST(FrameIntake, FramesWithoutAnInterfaceNameAreAlwaysRead) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  for (const CanFrame& f : periods(1, 10)) intake.feed(f);  // live SocketCAN: no name
  intake.flush();
  EXPECT_EQ(rec.samples.size(), 10U);
  EXPECT_TRUE(intake.interfaces().empty());
  EXPECT_EQ(intake.interface_note(), "");
}

TEST(FrameDecoder, SignalMapErrorsNameTheProblem) {
  auto loaded = dbc::load_dbc_file(RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc");
  ASSERT_TRUE(std::holds_alternative<dbc::Database>(loaded));
  auto db = std::make_shared<const dbc::Database>(std::get<dbc::Database>(std::move(loaded)));
  SignalMap map = SignalMap::bench_default();
  map.roles[static_cast<std::size_t>(Role::kSin)] = SignalRef{"RESOLVER_SAMPLE", "sine"};
  map.roles[static_cast<std::size_t>(Role::kIA)] = SignalRef{"CURRENTS", "i_a"};
  try {
    FrameDecoder d(db, map);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no signal 'sine'"), std::string::npos) << what;
    EXPECT_NE(what.find("no message 'CURRENTS'"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace resolver
