// The whole daemon pipeline on a log with every kind of bad line and frame:
// each is counted under its own reason in health_t, the good samples around
// them are all published, and nothing crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "daemon/app/pipeline.h"
#include "daemon/app/replay_runner.h"
#include "daemon/decode/bench_layout.h"
#include "drivers/candump/candump_line.h"

namespace resolver {
namespace {

struct RecordingSink final : OutputSink {
  std::vector<angle_t> angles;
  std::vector<dq_t> dqs;
  std::vector<estimate_t> estimates;
  std::vector<health_t> healths;
  void publish(const angle_t& m) override { angles.push_back(m); }
  void publish(const dq_t& m) override { dqs.push_back(m); }
  void publish(const estimate_t& m) override { estimates.push_back(m); }
  void publish(const model_fit_t&) override {}
  void publish(const health_t& m) override { healths.push_back(m); }
};

std::int64_t reason_count(const health_t& h, const std::string& reason) {
  for (std::size_t i = 0; i < h.reject_reason.size(); ++i) {
    if (h.reject_reason[i] == reason) return h.reject_count[i];
  }
  return 0;
}

TEST(PipelineBadInput, EveryProblemCountedNoGoodSampleLost) {
  const std::string path = std::string(RESOLVER_BINARY_DIR) + "/pipeline_bad_input.log";
  std::string text;
  auto frame_line = [&text](const CanFrame& f) {
    CanFrame g = f;
    g.set_iface("can0");
    append_candump_line(g, text);
  };
  // 20 good samples with BENCH_INFO; bad lines and frames in between.
  frame_line(bench::encode_bench_info(1'000'000, 3, 3, 16, 2000));
  for (int k = 0; k < 20; ++k) {
    const auto c = static_cast<std::uint8_t>(k);
    const std::int64_t t = 1'000'100 + 500LL * k;
    frame_line(bench::encode_resolver_sample(t, c, 0, 26000, static_cast<std::uint16_t>(100 * k)));
    frame_line(bench::encode_phase_currents(t + 1, c, 100, -50, -50));
    if (k == 3) text += "(1000.000000) can0 100#00112233445566ZZ\n";   // bad hex
    if (k == 4) text += "(1000.000000) can0 100#0011223\n";           // odd nibbles
    if (k == 5) text += "(1000.000000) can0 100#001122334455667788\n"; // 9 bytes classic
    if (k == 6) text += "can0 100#0011223344556677\n";                 // missing timestamp
    if (k == 8) {
      CanFrame bad = bench::encode_resolver_sample(t + 2, 99, 1, 1, 1);
      bad.data[7] ^= 0xFF;  // CRC broken
      frame_line(bad);
    }
    if (k == 9) {
      CanFrame unknown = bench::encode_phase_currents(t + 2, c, 0, 0, 0);
      unknown.id = 0x555;
      frame_line(unknown);
    }
    if (k == 10) text += "\n";  // blank lines are not errors
  }
  std::ofstream(path) << text;

  RecordingSink sink;
  std::ostringstream diag;
  DaemonConfig config;
  Pipeline pipeline(config, sink, diag);
  StopFlags flags;
  ReplayOptions ro;
  ro.path = path;
  ro.fast = true;
  ro.progress = false;
  const ReplayResult rr = run_replay(ro, pipeline, flags, diag);

  EXPECT_EQ(rr.bad_lines, 4U);
  // Fast replay reads the clock for frames 1, 17, 33, ... only; every frame
  // still goes through the chain (the counts below).
  EXPECT_EQ(rr.frames, 43U);
  EXPECT_EQ(pipeline.latency_total().count(), (rr.frames + kReplayLatencyEvery - 1) / kReplayLatencyEvery);
  ASSERT_FALSE(sink.healths.empty());
  const health_t& h = sink.healths.back();
  EXPECT_EQ(reason_count(h, "bad_hex"), 1);
  EXPECT_EQ(reason_count(h, "odd_nibbles"), 1);
  EXPECT_EQ(reason_count(h, "dlc_too_long"), 1);
  EXPECT_EQ(reason_count(h, "missing_timestamp"), 1);
  EXPECT_EQ(reason_count(h, "crc"), 1);
  EXPECT_EQ(reason_count(h, "unknown_id"), 1);
  EXPECT_EQ(h.frames_seen, 1 + 40 + 2);
  EXPECT_EQ(h.frames_decoded, 1 + 40);
  EXPECT_EQ(h.samples_complete, 20);
  EXPECT_EQ(h.samples_incomplete, 0);
  ASSERT_EQ(sink.angles.size(), 20U);
  for (std::size_t k = 0; k < 20; ++k) EXPECT_EQ(sink.angles[k].counter, static_cast<int>(k));
  // Messages name the file and line of each bad line.
  const std::string d = diag.str();
  EXPECT_NE(d.find(path + ":"), std::string::npos) << d;
  EXPECT_NE(d.find("[bad_hex]"), std::string::npos) << d;
}

TEST(PipelineWakeIds, CountsSamplesCompletedByAFrameOutsideWakeIds) {
  // Samples of RESOLVER_SAMPLE (0x100) + PHASE_CURRENTS (0x101), no reference:
  // 0x101 completes each one. Naming 0x102 in wake_ids is a mistake the
  // daemon must report (those samples waited for a wake-up); naming 0x101 is right.
  for (const std::uint32_t wake : {0x102U, 0x101U}) {
    RecordingSink sink;
    std::ostringstream diag;
    DaemonConfig config;
    Pipeline pipeline(config, sink, diag);
    pipeline.set_wake_ids({wake});  // what run_live does
    CanFrame info = bench::encode_bench_info(1'000'000, 3, 3, 16, 2000);
    pipeline.feed_untimed(info, 0);
    for (int k = 0; k < 40; ++k) {
      const auto c = static_cast<std::uint8_t>(k);
      const std::int64_t t = 1'000'100 + 500LL * k;
      pipeline.feed_untimed(bench::encode_resolver_sample(t, c, 0, 26000, static_cast<std::uint16_t>(100 * k)), 0);
      pipeline.feed_untimed(bench::encode_phase_currents(t + 1, c, 100, -50, -50), 0);
    }
    const CompletingFrames& done = pipeline.completing_frames();
    // The joiner learns the layout on the first two samples and emits them when
    // they leave its reorder window, max_counter_delta periods on; the samples
    // waiting behind them go out at once: none of these is completed by a frame.
    ASSERT_EQ(done.size(), 1U);
    EXPECT_EQ(done.at(0).first, 0x101U);
    EXPECT_EQ(done.at(0).second, pipeline.intake().stats().samples_complete - (config.max_counter_delta + 2));
    const std::int64_t quiet = pipeline.intake().rejects().get("completed_by_quiet_frame");
    if (wake == 0x102U) {
      EXPECT_EQ(quiet, done.at(0).second);
      EXPECT_NE(diag.str().find("completed by frame 0x101, which does not wake the reader"), std::string::npos)
          << diag.str();
    } else {
      EXPECT_EQ(quiet, 0) << diag.str();
    }
  }
}

TEST(PipelineBadInput, MissingLogIsAClearError) {
  RecordingSink sink;
  std::ostringstream diag;
  Pipeline pipeline(DaemonConfig{}, sink, diag);
  StopFlags flags;
  ReplayOptions ro;
  ro.path = "/nonexistent/demo.log";
  EXPECT_THROW(run_replay(ro, pipeline, flags, diag), std::runtime_error);
}

TEST(PipelineBadInput, BadDbcInConfigIsAUsageErrorNamingItsLine) {
  const std::string path = std::string(RESOLVER_BINARY_DIR) + "/pipeline_bad.dbc";
  std::ofstream(path) << "VERSION \"\"\nBO_ 256 RESOLVER_SAMPLE: 8 INVERTER\n SG_ counter : 0|8@1+ (1,0 [0|255] \"\" X\n";
  DaemonConfig config;
  config.dbc_path = path;
  RecordingSink sink;
  std::ostringstream diag;
  try {
    Pipeline pipeline(config, sink, diag);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {  // the parser's own, as it threw it: exit 2
    EXPECT_EQ(e.fault(), Fault::kUsage);
    EXPECT_EQ(e.where().file, path);
    EXPECT_EQ(e.where().line, 3U);
    EXPECT_NE(std::string(e.what()).find("pipeline_bad.dbc:3: "), std::string::npos) << e.what();
  }
}

/// Feeds the three frames of sample k at `t_us` (the default layout, BENCH_INFO at 2 kHz first).
void feed_sample(Pipeline& p, int k, std::int64_t t_us) {
  const auto c = static_cast<std::uint8_t>(k);
  p.feed_untimed(bench::encode_resolver_sample(t_us, c, 0, 26000, static_cast<std::uint16_t>(100 * k)), 0);
  p.feed_untimed(bench::encode_phase_currents(t_us + 1, c, 100, -50, -50), 0);
  p.feed_untimed(bench::encode_reference_angle(t_us + 2, c, 0), 0);
}

TEST(PipelineHealth, FramesThatWaitedInTheSocketDoNotMultiplyHealth) {
  // Live, tick() runs on the wall clock; a reader that lags reads frames
  // stamped seconds before the window tick() started. That is no step in the
  // input's clock: health stays at one per second, not one per read.
  RecordingSink sink;
  std::ostringstream diag;
  DaemonConfig config;
  config.model.enabled = false;
  Pipeline pipeline(config, sink, diag, true);
  constexpr std::int64_t kWall = 1'700'000'010'000'000;  // [us] 10 s ahead of the frames
  pipeline.tick(kWall);
  for (int k = 0; k < 2000; ++k) {  // 1 s of samples at 2 kHz
    feed_sample(pipeline, k, 1'700'000'000'000'000 + 500LL * k);
    pipeline.tick(kWall + 500LL * k);
  }
  EXPECT_LE(sink.healths.size(), 2U);
}

TEST(PipelineHealth, AStepBackInTheLogKeepsHealthComing) {
  RecordingSink sink;
  std::ostringstream diag;
  DaemonConfig config;
  config.model.enabled = false;
  Pipeline pipeline(config, sink, diag);
  pipeline.feed_untimed(bench::encode_bench_info(1'700'000'000'000'000, 3, 3, 16, 2000), 0);
  // 3 s (health at 1 s and 2 s), then the stamps step back 2 s and run 3 s more: the window
  // restarts at the step, health at 1 s and 2 s after it. Without the restart the second piece
  // would publish once (its stamps pass the old window's end only after 1 s).
  for (int k = 0; k < 12000; ++k) {
    feed_sample(pipeline, k, 1'700'000'000'000'000 + 500LL * k - (k >= 6000 ? 2'000'000 : 0));
  }
  EXPECT_EQ(sink.healths.size(), 4U);
  EXPECT_EQ(pipeline.intake().rejects().get("timestamp_step_back"), 1);
}


// Issue 25: a config reload (SIGHUP) swaps the config between two frames and keeps the
// run's record: frame and sample counts, rejects, health counts and the sample index.
class PipelineReload : public ::testing::Test {
 protected:
  void feed_samples(Pipeline& p, int from, int to) {
    for (int k = from; k < to; ++k) {
      const auto c = static_cast<std::uint8_t>(k);
      const std::int64_t t = 1'000'000 + 500LL * k;
      const double theta = 0.02 * k;
      p.feed_untimed(bench::encode_resolver_sample(t, c, static_cast<std::int16_t>(26000 * std::sin(theta)),
                                                   static_cast<std::int16_t>(26000 * std::cos(theta)),
                                                   static_cast<std::uint16_t>(theta / (2 * 3.141592653589793) * 65536)),
                     0);
      p.feed_untimed(bench::encode_phase_currents(t + 1, c, 100, -50, -50), 0);
      if (k == 5) {
        CanFrame bad = bench::encode_resolver_sample(t + 2, c, 1, 1, 1);
        bad.data[7] ^= 0xFF;  // CRC broken
        p.feed_untimed(bad, 0);
      }
    }
  }
  RecordingSink sink;
  std::ostringstream diag;
};

TEST_F(PipelineReload, KeepsCountersRejectsHealthAndTheSampleIndex) {
  Pipeline pipeline(DaemonConfig{}, sink, diag);
  feed_samples(pipeline, 0, 100);
  const std::int64_t seen = pipeline.intake().stats().frames_seen;
  DaemonConfig fresh = parse_daemon_config("[health]\noutlier_sigmas = 9.0\n", "fresh.toml");
  const Pipeline::Reload& r = pipeline.reload(fresh);
  EXPECT_TRUE(r.estimate_kept);
  // The last sample out before it: 99, or 98 while the 100th waits for its last frame.
  EXPECT_GE(r.sample_index, 98);
  EXPECT_LE(r.sample_index, 99);
  EXPECT_NEAR(r.t_s, static_cast<double>(r.sample_index) * 0.0005, 1e-9);
  EXPECT_EQ(pipeline.intake().stats().frames_seen, seen);
  feed_samples(pipeline, 100, 200);
  pipeline.finish();
  EXPECT_EQ(pipeline.intake().stats().frames_seen, seen + 200);  // 2 frames a sample; the bad one came before
  EXPECT_EQ(pipeline.intake().rejects().all().at("crc"), 1);
  EXPECT_EQ(pipeline.signal_health().summary().samples, 200);
  EXPECT_EQ(pipeline.signal_health().monitor().config().outlier_sigmas, 9.0);
  ASSERT_EQ(sink.angles.size(), 200u);
  for (std::size_t i = 1; i < sink.angles.size(); ++i) {
    ASSERT_GT(sink.angles[i].sample_index, sink.angles[i - 1].sample_index) << i;
  }
  ASSERT_EQ(pipeline.reloads().size(), 1u);
}

TEST_F(PipelineReload, ANewLayoutDecodesFromTheNextFrameAndTheIndexGoesOn) {
  Pipeline pipeline(DaemonConfig{}, sink, diag);
  feed_samples(pipeline, 0, 50);
  // The phase currents swapped: another layout, the same frames still decode.
  const DaemonConfig fresh = parse_daemon_config(
      "[layout.signals]\nsin = \"RESOLVER_SAMPLE.sin\"\ncos = \"RESOLVER_SAMPLE.cos\"\n"
      "rd_angle = \"RESOLVER_SAMPLE.rd_angle\"\ni_a = \"PHASE_CURRENTS.i_b\"\ni_b = \"PHASE_CURRENTS.i_a\"\n"
      "i_c = \"PHASE_CURRENTS.i_c\"\n",
      "swapped.toml");
  const Pipeline::Reload& r = pipeline.reload(fresh);
  EXPECT_NE(r.what.find("new layout"), std::string::npos) << r.what;
  feed_samples(pipeline, 50, 100);
  pipeline.finish();
  EXPECT_EQ(pipeline.intake().stats().samples_complete, 100);
  ASSERT_EQ(sink.angles.size(), 100u);
  EXPECT_EQ(sink.angles.back().sample_index, 99);
}

TEST_F(PipelineReload, AConfigThatCannotRunChangesNothing) {
  Pipeline pipeline(DaemonConfig{}, sink, diag);
  feed_samples(pipeline, 0, 20);
  const DaemonConfig bad = parse_daemon_config("[layout.signals]\ni_a = \"PHASE_CURRENTS.i_a\"\n", "bad.toml");
  EXPECT_THROW((void)pipeline.reload(bad), InputError);  // the map does not fit the DBC: usage
  EXPECT_TRUE(pipeline.reloads().empty());
  feed_samples(pipeline, 20, 40);
  EXPECT_GE(pipeline.intake().stats().samples_complete, 39);  // the 40th may still be open
}

}  // namespace
}  // namespace resolver

namespace resolver {
namespace {

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A config in its own folder names its DBC relatively: found there, not in the
// working directory; the DBC's findings are printed once each with file:line.
TEST(PipelineDbcWarnings, RelativeDbcFromTheConfigFolderAndItsWarningsPrintedOnce) {
  const std::string dir = std::string(RESOLVER_BINARY_DIR) + "/pipeline_dbc_warnings";
  std::filesystem::create_directories(dir);
  std::ifstream bench(std::string(RESOLVER_SOURCE_DIR) + "/proto/resolver_bench.dbc");
  std::stringstream dbc;
  dbc << bench.rdbuf();
  const auto lines_before = static_cast<std::size_t>(std::count(std::istreambuf_iterator<char>(dbc),
                                                                std::istreambuf_iterator<char>(), '\n'));
  std::string text = dbc.str();
  if (!text.empty() && text.back() != '\n') text += "\n";
  text += "FOO_ 1 2 3\nCM_ SG_ 256 no_such_signal \"x\";\n";
  std::ofstream(dir + "/with_warnings.dbc") << text;
  std::ofstream(dir + "/bench.toml") << "[layout]\ndbc = \"with_warnings.dbc\"\n";

  const DaemonConfig config = load_daemon_config(dir + "/bench.toml");
  RecordingSink sink;
  std::ostringstream diag;
  Pipeline pipeline(config, sink, diag);
  const std::string out = diag.str();
  const std::string file = dir + "/with_warnings.dbc:";
  const std::string unknown = file + std::to_string(lines_before + 1) + ": unknown keyword 'FOO_'";
  const std::string comment = file + std::to_string(lines_before + 2) + ": CM_ SG_ refers to unknown signal 256 no_such_signal";
  EXPECT_EQ(occurrences(out, unknown), 1U) << out;
  EXPECT_EQ(occurrences(out, comment), 1U) << out;
}

}  // namespace
}  // namespace resolver
