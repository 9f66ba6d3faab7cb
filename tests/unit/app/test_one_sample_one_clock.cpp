// One sample, one clock (issue 12.7, issue 16.3): resolver-model reads exactly
// the samples, at exactly the times, that resolverd's processor gets, also on a
// log whose timestamps step back 1 s and later jump forward a day; and no
// sample is lost to either.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "daemon/app/pipeline.h"
#include "daemon/app/replay_runner.h"
#include "drivers/candump/candump_writer.h"
#include "tools/model/log_samples.h"
#include "tools/sim/bench_simulator.h"

namespace resolver {
namespace {

class NullSink : public OutputSink {
 public:
  void publish(const angle_t&) override {}
  void publish(const dq_t&) override {}
  void publish(const estimate_t&) override {}
  void publish(const model_fit_t&) override {}
  void publish(const health_t&) override {}
};

constexpr std::int64_t kStepBackAt = 1000;  // sample index where the stamps go back 1 s
constexpr std::int64_t kJumpAt = 2500;      // ... and where they jump forward a day

/// 2 s at 200 r/min (4000 samples at 2 kHz) with odd time written into the log.
std::string write_odd_time_log(std::uint64_t& samples) {
  const std::string path = std::string(RESOLVER_BINARY_DIR) + "/one_clock_" + std::to_string(::getpid()) + ".log";
  SimConfig config;
  config.profile = {{2.0, 200.0, 200.0}};
  BenchSimulator sim(config);
  CandumpWriter writer(path);
  SimSample s{};
  std::vector<CanFrame> frames;
  samples = 0;
  while (sim.next(s)) {
    frames.clear();
    sim.append_frames(s, frames);
    const auto k = static_cast<std::int64_t>(s.index);
    for (CanFrame& f : frames) {
      if (k >= kStepBackAt) f.timestamp_us -= 1'000'000;
      if (k >= kJumpAt) f.timestamp_us += 86'400'000'000;
      writer.write(f);
    }
    ++samples;
  }
  writer.close();
  return path;
}

/// What resolverd --replay LOG [--from --to] feeds its processor, and what it counted.
struct Replayed {
  std::vector<Sample> samples;
  RejectCounters rejects;
  std::string diagnostics;
};

Replayed replay(const std::string& path, const DaemonConfig& config, const SampleSlice& slice = {}) {
  NullSink sink;
  std::ostringstream diag;
  Pipeline pipeline(config, sink, diag, false, slice);
  Replayed out;
  pipeline.set_sample_observer([&](const Sample& s) { out.samples.push_back(s); });
  StopFlags flags;
  ReplayOptions ro;
  ro.path = path;
  ro.fast = true;
  ro.progress = false;
  run_replay(ro, pipeline, flags, diag);
  out.rejects = pipeline.intake().rejects();
  out.diagnostics = diag.str();
  return out;
}

DaemonConfig input_only() {
  DaemonConfig config;
  config.model.enabled = false;  // only the input side is under test
  return config;
}

TEST(OneSampleOneClock, ResolverModelReadsWhatTheProcessorGets) {
  std::uint64_t simulated = 0;
  const std::string path = write_odd_time_log(simulated);
  const DaemonConfig config = input_only();
  const Replayed replayed = replay(path, config);
  const std::vector<Sample>& live = replayed.samples;
  const std::string& diag = replayed.diagnostics;
  const LogSamples offline = read_log_samples(path, nullptr, config);
  std::remove(path.c_str());

  // Every sample decoded: the step back and the jump are counted, nothing is lost.
  ASSERT_EQ(live.size(), simulated) << diag;
  EXPECT_EQ(replayed.rejects.get("timestamp_step_back"), 1) << diag;
  EXPECT_EQ(replayed.rejects.get("timestamp_jump"), 1) << diag;
  EXPECT_EQ(replayed.rejects.total(), 2) << diag;
  // Counter time straight through both: t = index / 2 kHz, exactly (an integer over a power-of-ten rate).
  for (const Sample& s : live) ASSERT_DOUBLE_EQ(s.t, static_cast<double>(s.index - live.front().index) / 2000.0) << s.index;

  ASSERT_EQ(offline.input.samples.size(), live.size());
  for (std::size_t i = 0; i < live.size(); ++i) {
    const Sample& a = live[i];
    const Sample& b = offline.input.samples[i];
    SCOPED_TRACE("sample " + std::to_string(i));
    ASSERT_EQ(a.t, b.t);
    ASSERT_EQ(a.index, b.index);
    ASSERT_EQ(a.utime, b.utime);
    ASSERT_EQ(a.has_rd, b.has_rd);
    ASSERT_EQ(a.theta_rd, b.theta_rd);
    ASSERT_EQ(a.has_sincos, b.has_sincos);
    ASSERT_EQ(a.sin, b.sin);
    ASSERT_EQ(a.cos, b.cos);
    ASSERT_EQ(a.has_ref, b.has_ref);
    ASSERT_EQ(a.theta_m_ref, b.theta_m_ref);
    ASSERT_EQ(a.has_currents, b.has_currents);
    ASSERT_EQ(a.i_a, b.i_a);
    ASSERT_EQ(a.i_b, b.i_b);
    ASSERT_EQ(a.i_c, b.i_c);
  }
}

TEST(OneSampleOneClock, SliceIsTheSameForBoth) {
  std::uint64_t simulated = 0;
  const std::string path = write_odd_time_log(simulated);
  const DaemonConfig config = input_only();
  SampleSlice slice;
  slice.from_s = 0.25;
  slice.to_s = 1.5;
  const std::vector<Sample> live = replay(path, config, slice).samples;
  LogReadOptions lo;
  lo.slice = slice;
  const LogSamples offline = read_log_samples(path, nullptr, config, lo);
  std::remove(path.c_str());
  // [0.25, 1.5] s at 2 kHz: samples 500 .. 3000.
  ASSERT_EQ(live.size(), 2501U);
  EXPECT_DOUBLE_EQ(live.front().t, 0.25);
  EXPECT_DOUBLE_EQ(live.back().t, 1.5);
  ASSERT_EQ(offline.input.samples.size(), live.size());
  for (std::size_t i = 0; i < live.size(); ++i) ASSERT_EQ(live[i].t, offline.input.samples[i].t);
}

}  // namespace
}  // namespace resolver
