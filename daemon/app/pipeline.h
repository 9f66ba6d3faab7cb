// resolverd's data flow — start reading here.
//
//   source (candump log replay | SocketCAN)          daemon/app/main.cpp
//     │ CanFrame
//     ▼
//   FrameIntake: DBC decode, CRC, counters, join     daemon/decode/
//     │ BenchSample (one control period)
//     ▼
//   SampleProcessor: estimate, compensate, dq, ripple daemon/core/estimation/ (pure)
//     │ SampleOutput
//     ▼
//   Pipeline: build angle_t / dq_t / estimate_t / health_t, decimate, publish
//     └─ LiveModelFit: model_fit_t per window of revolutions (second thread)  live_model_fit.h
//     │
//     ▼
//   OutputSink (LcmOutput on LCM, or a recorder in tests)
//
// The pipeline is single-threaded and purely reactive: every call to feed()
// runs the whole chain for that frame. Time is frame time (log or kernel
// timestamps); the caller passes the frame's arrival time only for latency.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <ostream>
#include <utility>
#include <vector>

#include "daemon/app/completing_frames.h"
#include "daemon/app/daemon_config.h"
#include "daemon/app/latency_histogram.h"
#include "daemon/app/live_model_fit.h"
#include "daemon/app/output_sink.h"
#include "daemon/app/problem_log.h"
#include "daemon/app/run_summary.h"
#include "daemon/app/signal_health_log.h"
#include "daemon/core/estimation/sample_processor.h"
#include "daemon/decode/frame_intake.h"

namespace resolver {

/// The config's DBC (or the built-in one) with its signal map. Throws ConfigError
/// naming the DBC and config at fault. Also used by resolver-model --config.
[[nodiscard]] std::shared_ptr<const FrameDecoder> make_frame_decoder(const DaemonConfig& config);

class Pipeline {
 public:
  using Clock = std::chrono::steady_clock;

  /// Loads the DBC and builds the chain. Throws ConfigError (bad DBC, signal map).
  /// `realtime`: live input (the model fit never holds up the reader; see live_model_fit.h).
  Pipeline(const DaemonConfig& config, OutputSink& sink, std::ostream& diagnostics, bool realtime = false);

  /// Runs one frame through the chain. `line` is its log line (0 live),
  /// `arrival` when it was read (for latency). Cannot fail.
  void feed(const CanFrame& frame, std::uint64_t line, Clock::time_point arrival);
  /// The same without the latency measurement, i.e. without reading the clock
  /// (two clock reads were ~9 % of a fast replay): replay times one frame in
  /// kReplayLatencyEvery and feeds the others through here.
  void feed_untimed(const CanFrame& frame, std::uint64_t line);
  /// Counts a problem found before a frame existed (malformed log line).
  void count_problem(std::string_view reason, const std::string& message);
  /// End of input: emit the open sample, publish a final health_t.
  void finish();
  /// Log loop: counters and joins restart, estimates and statistics stay.
  void restart_sequence() {
    intake_.restart_sequence();
    anchored_ = false;
  }
  /// Live idle time: publishes health_t when a second has passed since the
  /// last one even if no frame arrived. now_us [us] on the frames' clock.
  void tick(std::int64_t now_us);
  /// Compensate with a persisted alpha until the estimator converges.
  void seed_alpha(double alpha) { processor_.seed_alpha(alpha); }
  /// Compensate with a persisted or loaded model until the live fit has one.
  void seed_model(Model model) { processor_.set_model(std::move(model), 0, 0.0); }
  /// Compensate with an exported table (resolverd --calibration).
  void use_table(CalibrationTable table) { processor_.set_table(std::move(table)); }
  /// Cumulative frames dropped by the kernel (SO_RXQ_OVFL), for health_t.
  void set_kernel_drops(std::int64_t drops) { kernel_drops_ = drops; }

  [[nodiscard]] const FrameIntake& intake() const { return intake_; }
  [[nodiscard]] const SampleProcessor& processor() const { return processor_; }
  [[nodiscard]] const RunSummary& summary() const { return summary_; }
  [[nodiscard]] const LatencyHistogram& latency_total() const { return latency_total_; }
  [[nodiscard]] std::int64_t samples() const { return samples_; }
  /// Which frame IDs completed the samples (the ones [can] wake_ids should name).
  [[nodiscard]] const CompletingFrames& completing_frames() const { return completing_frames_; }
  /// The frames that wake the live reader now (empty = every frame): a sample
  /// completed by another frame waited for a wake-up and is counted.
  void set_wake_ids(std::vector<std::uint32_t> ids) { wake_ids_ = std::move(ids); }
  /// nullptr when [model] enabled = false.
  [[nodiscard]] const LiveModelFit* model_fit() const { return model_fit_.get(); }
  /// Signal faults (LOS, DOS, LOT, ...) and the sin/cos amplitude.
  [[nodiscard]] const SignalHealthLog& signal_health() const { return signal_health_; }

 private:
  void on_sample(const BenchSample& sample);
  void on_bench_info(const BenchInfo& info);
  void publish_estimate(std::int64_t utime, const BenchSample& sample);
  void feed_model_fit(const SampleInput& in, const BenchSample& sample);
  void publish_health(std::int64_t utime);
  void note_completing_frame(const CanFrame& frame);

  DaemonConfig config_;
  OutputSink& sink_;
  ProblemLog problems_;
  FrameIntake intake_;
  SampleProcessor processor_;
  RunSummary summary_;
  LatencyHistogram latency_window_;
  LatencyHistogram latency_total_;
  std::int64_t samples_ = 0;
  CompletingFrames completing_frames_;
  std::vector<std::uint32_t> wake_ids_;
  std::int64_t last_frame_us_ = 0;
  std::int64_t health_window_start_us_ = -1;
  std::int64_t frames_at_window_start_ = 0;
  std::int64_t last_sample_index_ = 0;
  std::uint8_t last_counter_ = 0;
  bool bench_info_seen_ = false;
  // Sample clock: time = anchor_t + (index - anchor_index) / sample_rate.
  double sample_rate_hz_ = 0.0;
  bool anchored_ = false;
  std::int64_t anchor_index_ = 0;
  double anchor_t_ = 0.0;
  std::int64_t last_index_ = 0;   ///< index of the previous sample
  double last_frame_t_ = 0.0;     ///< [s] frame time of the previous sample
  double sample_time(const BenchSample& sample);
  std::int64_t kernel_drops_ = 0;
  std::unique_ptr<LiveModelFit> model_fit_;
  SignalHealthLog signal_health_;
};

}  // namespace resolver
