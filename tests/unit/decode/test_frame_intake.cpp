// Frames of the default layout through the DBC-driven intake: decoding,
// joining, and every kind of bad frame counted without touching good samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/bench_layout.h"
#include "daemon/decode/frame_intake.h"

namespace resolver {
namespace {

std::shared_ptr<const FrameDecoder> bench_decoder() {
  auto db = std::make_shared<const dbc::Database>(dbc::load_dbc_file(RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc"));
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

// Issue 25 ("Trust"): frames of neighbouring periods out of order, as a USB-CAN
// adapter's buffering delivers them, are reordered, not lost; what is lost is at
// most what is missing; a late frame never makes the sample index jump.
std::vector<CanFrame> periods(int first, int count) {
  std::vector<CanFrame> f;
  for (int k = first; k < first + count; ++k) push_sample(f, k);
  return f;
}

std::int64_t lcg(std::uint64_t& state) {
  state = state * 6364136223846793005ULL + 1442695040888963407ULL;
  return static_cast<std::int64_t>(state >> 33U);
}

TEST(FrameIntake, FramesShuffledWithinTheWindowAreReorderedNotLost) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames = periods(1, 600);  // counters wrap twice
  // Arrival up to 3 ms (6 periods) late, log order = arrival order.
  std::uint64_t seed = 25;
  std::vector<std::pair<std::int64_t, CanFrame>> arrival;
  for (const CanFrame& f : frames) arrival.emplace_back(f.timestamp_us + lcg(seed) % 3000, f);
  std::stable_sort(arrival.begin(), arrival.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [t, f] : arrival) {
    CanFrame g = f;
    g.timestamp_us = t;
    intake.feed(g);
  }
  intake.flush();
  ASSERT_EQ(rec.samples.size(), 600U);
  for (std::size_t i = 0; i < rec.samples.size(); ++i) {
    const BenchSample& s = rec.samples[i];
    EXPECT_EQ(s.index, static_cast<std::int64_t>(i) + 1) << i;  // in order, no jump
    EXPECT_TRUE(s.complete()) << i;
    EXPECT_DOUBLE_EQ(s.get(Role::kSin), static_cast<std::int16_t>(100 * s.index)) << i;  // its own values
  }
  EXPECT_EQ(intake.stats().frames_lost, 0);
  EXPECT_GT(intake.rejects().get("frames_reordered"), 100);
  EXPECT_EQ(intake.rejects().total(), intake.rejects().get("frames_reordered")) << "only reordering is counted";
}

TEST(FrameIntake, LostFramesAreWhatIsMissingNeverMore) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames = periods(1, 600);
  std::uint64_t seed = 7;
  std::vector<std::pair<std::int64_t, CanFrame>> arrival;
  std::int64_t deleted = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i > 30 && i + 30 < frames.size() && lcg(seed) % 50 == 0) {
      ++deleted;  // lost on the bus
      continue;
    }
    arrival.emplace_back(frames[i].timestamp_us + lcg(seed) % 3000, frames[i]);
  }
  std::stable_sort(arrival.begin(), arrival.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [t, f] : arrival) intake.feed(f);
  intake.flush();
  ASSERT_GT(deleted, 10);
  EXPECT_EQ(intake.stats().frames_lost, deleted);
  EXPECT_EQ(intake.rejects().get("frames_lost"), deleted);
  EXPECT_EQ(intake.rejects().get("counter_wrong_sequence"), 0);
  std::int64_t missing = 0;
  for (std::size_t i = 0; i < rec.samples.size(); ++i) {
    EXPECT_EQ(rec.samples[i].index, static_cast<std::int64_t>(i) + 1);
    missing += 3 - std::popcount(rec.samples[i].slots_present);
  }
  EXPECT_EQ(missing, deleted);
}

TEST(FrameIntake, ALateFrameDoesNotMoveTheSampleIndex) {
  // Period 10's REFERENCE_ANGLE comes after period 11's frames: before, the index
  // went 10, 266 (the counter read as wrapped), 268, with no gap counted.
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames = periods(1, 20);
  const CanFrame late = frames[3 * 9 + 2];
  frames.erase(frames.begin() + 3 * 9 + 2);
  frames.insert(frames.begin() + 3 * 10 + 2, late);
  for (const CanFrame& f : frames) intake.feed(f);
  intake.flush();
  ASSERT_EQ(rec.samples.size(), 20U);
  for (std::size_t i = 0; i < rec.samples.size(); ++i) {
    EXPECT_EQ(rec.samples[i].index, static_cast<std::int64_t>(i) + 1);
    EXPECT_TRUE(rec.samples[i].complete()) << i;
  }
  EXPECT_EQ(intake.rejects().get("frames_reordered"), 1);
  EXPECT_EQ(intake.rejects().total(), 1);
  ASSERT_EQ(rec.problems.size(), 1U);
  EXPECT_NE(rec.problems[0].find("REFERENCE_ANGLE counter 10 came after a frame of counter 11: reordered"),
            std::string::npos)
      << rec.problems[0];
}

TEST(FrameIntake, AFrameLaterThanTheWindowIsLateNotLost) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames = periods(1, 30);
  const CanFrame late = frames[3 * 4 + 1];  // period 5's PHASE_CURRENTS ...
  frames.erase(frames.begin() + 3 * 4 + 1);
  frames.insert(frames.begin() + 3 * 15 - 1, late);  // ... after period 15's frames
  for (const CanFrame& f : frames) intake.feed(f);
  intake.flush();
  ASSERT_EQ(rec.samples.size(), 30U);
  for (std::size_t i = 0; i < rec.samples.size(); ++i) EXPECT_EQ(rec.samples[i].index, static_cast<std::int64_t>(i) + 1);
  EXPECT_FALSE(rec.samples[4].complete());  // used without it: it came too late
  EXPECT_EQ(intake.rejects().get("frames_late"), 1);
  EXPECT_EQ(intake.rejects().get("sample_incomplete"), 1);
  EXPECT_EQ(intake.stats().frames_lost, 0) << "it came: not lost";
  EXPECT_EQ(intake.rejects().get("counter_wrong_sequence"), 0);
  const auto it = std::find_if(rec.problems.begin(), rec.problems.end(),
                               [](const std::string& p) { return p.rfind("frames_late", 0) == 0; });
  ASSERT_NE(it, rec.problems.end());
  EXPECT_NE(it->find("PHASE_CURRENTS counter 5 is 10 periods behind the newest (15), more than [layout] "
                     "max_counter_delta = 8: it came after its sample was used, dropped (not lost"),
            std::string::npos)
      << *it;
}

TEST(FrameIntake, ANewSequenceIsCountedOnceWithTheIndexStep) {
  Recorder rec;
  FrameIntake intake(bench_decoder(), 8, rec.callbacks());
  std::vector<CanFrame> frames = periods(1, 30);
  std::vector<CanFrame> again = periods(1, 30);  // logs appended: the counter starts over
  for (CanFrame& f : again) f.timestamp_us += 1'000'000;
  frames.insert(frames.end(), again.begin(), again.end());
  for (const CanFrame& f : frames) intake.feed(f);
  intake.flush();
  ASSERT_EQ(rec.samples.size(), 60U);
  EXPECT_EQ(intake.rejects().get("counter_wrong_sequence"), 1);
  EXPECT_EQ(intake.rejects().total(), 1);
  EXPECT_EQ(intake.stats().frames_lost, 0);
  EXPECT_EQ(rec.samples[30].index - rec.samples[29].index, 227);  // counter 30 -> 1, as the u8 counter counts
  for (std::size_t i = 0; i < rec.samples.size(); ++i) EXPECT_TRUE(rec.samples[i].complete()) << i;
  ASSERT_EQ(rec.problems.size(), 1U);
  EXPECT_NE(rec.problems[0].find("RESOLVER_SAMPLE counter jumped to 1 from 30: 226 periods missing as the 8-bit "
                                 "counter counts, more than [layout] max_counter_delta = 8, or a new sequence (a "
                                 "restart, logs appended): resynchronised, the sample index advances by 227"),
            std::string::npos)
      << rec.problems[0];
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
  auto db = std::make_shared<const dbc::Database>(dbc::load_dbc_file(RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc"));
  SignalMap map = SignalMap::bench_default();
  map.roles[static_cast<std::size_t>(Role::kSin)] = SignalRef{"RESOLVER_SAMPLE", "sine"};
  map.roles[static_cast<std::size_t>(Role::kIA)] = SignalRef{"CURRENTS", "i_a"};
  try {
    FrameDecoder d(db, map, Where::at_file("bench.toml"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.fault(), Fault::kUsage);  // the config's map: exit 2
    // The config, its [layout], and the DBC it does not fit.
    EXPECT_EQ(what.rfind("bench.toml: [layout]: signal map does not fit the DBC " + db->source + ":\n  - ", 0), 0U)
        << what;
    EXPECT_NE(what.find("no signal 'sine'"), std::string::npos) << what;
    EXPECT_NE(what.find("no message 'CURRENTS'"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace resolver
