// Frames of the default layout through the DBC-driven intake: decoding,
// joining, and every kind of bad frame counted without touching good samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
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
