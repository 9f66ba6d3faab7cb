// resolverd's data flow — start reading here.
//
//   source (candump / ASC / CSV log replay | SocketCAN) daemon/app/main.cpp, log_input.h
//     │ CanFrame (or RowSample for a CSV row)
//     ▼
//   SampleStream: DBC decode, units, CRC, counters,  daemon/decode/sample_stream.h
//     join, sample clock, slice
//     │ Sample (one control period; the same as resolver-model reads)
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
// runs the whole chain for that frame. Sample time is the sample clock's
// (counter time where there is one, daemon/decode/sample_clock.h); health_t
// runs on frame (or row) time; the caller passes the frame's arrival time only
// for latency.
//
// A config reload (SIGHUP) is swapped into the same pipeline (reload()): what the
// run has counted, its sample index and, with the same model, what it has learned
// carry on, so one report covers the whole run.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
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
#include "daemon/core/model/run_estimate.h"
#include "daemon/decode/sample_stream.h"

namespace resolver {

/// The config's DBC (or the built-in one) with its signal map. Throws ConfigError
/// naming the DBC and config at fault. Also used by resolver-model --config.
[[nodiscard]] std::shared_ptr<const FrameDecoder> make_frame_decoder(const DaemonConfig& config);
/// The sample stream's settings from the config ([bench], [layout], [input.csv]) and a slice.
[[nodiscard]] SampleStreamConfig sample_stream_config(const DaemonConfig& config, const SampleSlice& slice = {});
/// How messages name the layout in use: "the default bench layout (proto/resolver_bench.dbc ...: RESOLVER_SAMPLE
/// 0x100 (sin = sin, ...), ...)" or "the layout of my.dbc from cfg.toml (...)".
[[nodiscard]] std::string describe_layout(const DaemonConfig& config, const FrameDecoder& decoder);

/// The layout a calibration belongs to: `id` is 8 hex digits of CRC-32 over what turns
/// frames into samples: each mapped message's name, ID and DLC, and for each role, the
/// counter and the CRC its signal's name, bits, byte order, sign, scale, offset and unit
/// conversion. A renamed, moved or re-commented DBC is the same layout; a changed
/// scaling, ID, bit position or mapping is not. `description` says it in words
/// (describe_layout()). Throws ConfigError like make_frame_decoder().
struct LayoutIdentity {
  std::string id;
  std::string description;
};
[[nodiscard]] LayoutIdentity layout_identity(const DaemonConfig& config);
/// The same for a decoder already made from `config`. Cannot fail.
[[nodiscard]] LayoutIdentity layout_identity(const DaemonConfig& config, const FrameDecoder& decoder);

class Pipeline {
 public:
  using Clock = std::chrono::steady_clock;

  /// Loads the DBC and builds the chain. Throws ConfigError (bad DBC, signal map).
  /// `realtime`: live input (the model fit never holds up the reader; see live_model_fit.h).
  /// `slice`: only samples with t in [from, to] are processed (--from/--to).
  Pipeline(const DaemonConfig& config, OutputSink& sink, std::ostream& diagnostics, bool realtime = false,
           const SampleSlice& slice = {});

  /// Runs one frame through the chain. `line` is its log line (0 live),
  /// `arrival` when it was read (for latency). Cannot fail.
  void feed(const CanFrame& frame, std::uint64_t line, Clock::time_point arrival);
  /// The same without the latency measurement, i.e. without reading the clock
  /// (two clock reads were ~9 % of a fast replay): replay times one frame in
  /// kReplayLatencyEvery and feeds the others through here.
  void feed_untimed(const CanFrame& frame, std::uint64_t line);
  /// Runs one row of a frameless input (CSV) through the chain: health_t then
  /// counts rows as frames (seen, decoded, rejected by reason). Cannot fail.
  void feed_row(const RowSample& row, std::uint64_t line);
  /// Counts a problem found before a frame existed (malformed log line).
  void count_problem(std::string_view reason, const std::string& message);
  /// End of input: emit the open sample, publish a final health_t.
  void finish();
  /// Log loop: counters and joins restart, estimates and statistics stay; the
  /// signal health does not read the joint between passes as a fault.
  void restart_sequence() {
    stream_.restart_sequence();
    signal_health_.new_pass();
  }
  /// Live idle time: publishes health_t when a second has passed since the
  /// last one even if no frame arrived. now_us [us] on the frames' clock.
  void tick(std::int64_t now_us);
  /// Compensate with a persisted or loaded model until this run's estimate (the live
  /// fit's, or an older method's own) has one.
  void seed_model(Model model) { processor_.set_model(std::move(model), 0, 0.0); }
  /// Compensate with an exported table (resolverd --calibration); kept across reloads.
  void use_table(CalibrationTable table) {
    table_ = table;
    processor_.set_table(std::move(table));
  }

  /// One config reload (SIGHUP), as the run report lists it.
  struct Reload {
    double t_s = 0.0;               ///< [s] sample time of the last sample before it, from the first sample
    std::int64_t sample_index = 0;  ///< that sample's index
    std::int64_t utime = 0;         ///< [us] that sample's utime (bench time)
    bool estimate_kept = false;     ///< the learned estimate carried on
    std::string what;               ///< what changed and what carried on, one line
  };
  /// Swaps in `fresh` between two frames and keeps the run's record: frame and sample
  /// counts, rejects, signal-health counts, the sample clock and index, the report's
  /// statistics and the live fit's window counts; and the learned estimate when the model
  /// is unchanged (same method, [model] effects and custom effects, pole pairs). A new
  /// layout restarts counters and joins (as a log loop does). Throws (ConfigError, or what
  /// building the new parts throws) before anything changes when `fresh` cannot run.
  const Reload& reload(const DaemonConfig& fresh);
  /// Every reload so far, in order.
  [[nodiscard]] const std::vector<Reload>& reloads() const { return reloads_; }
  /// Cumulative frames dropped by the kernel (SO_RXQ_OVFL), for health_t.
  void set_kernel_drops(std::int64_t drops) { kernel_drops_ = drops; }

  [[nodiscard]] const FrameIntake& intake() const { return stream_.intake(); }
  [[nodiscard]] const SampleStream& stream() const { return stream_; }
  /// True once the input has passed --to: the rest of the log is not needed.
  [[nodiscard]] bool past_slice_end() const { return stream_.past_slice_end(); }
  [[nodiscard]] const DaemonConfig& config() const { return config_; }
  [[nodiscard]] const SampleProcessor& processor() const { return processor_; }
  [[nodiscard]] const RunSummary& summary() const { return summary_; }
  [[nodiscard]] const LatencyHistogram& latency_total() const { return latency_total_; }
  [[nodiscard]] std::int64_t samples() const { return samples_; }
  /// Which frame IDs completed the samples (the ones [can] wake_ids should name).
  [[nodiscard]] const CompletingFrames& completing_frames() const { return completing_frames_; }
  /// The frames that wake the live reader now (empty = every frame): a sample
  /// completed by another frame waited for a wake-up and is counted.
  void set_wake_ids(std::vector<std::uint32_t> ids) { wake_ids_ = std::move(ids); }
  /// Sees every sample the processor gets, as it gets it: the samples and times
  /// resolver-model reads from the same log must be exactly these (a test checks).
  void set_sample_observer(std::function<void(const Sample&)> observer) { observer_ = std::move(observer); }
  /// nullptr when [model] enabled = false.
  [[nodiscard]] const LiveModelFit* model_fit() const { return model_fit_.get(); }
  /// Method kModel: every window's model this run, combined (after finish(), the
  /// processor's estimate is this; run_estimate.h).
  [[nodiscard]] const RunEstimate& run_estimate() const { return run_estimate_; }
  /// Signal faults (LOS, DOS, LOT, ...) and the sin/cos amplitude.
  [[nodiscard]] const SignalHealthLog& signal_health() const { return signal_health_; }

 private:
  void on_sample(const Sample& sample, std::uint8_t counter);
  void on_bench_info(const BenchInfo& info);
  /// Takes every model the live fit finished since the last call, oldest first; method
  /// kModel adds each to the run's estimate and compensates with the newest (true).
  bool adopt_live_fit();
  void publish_estimate(const Sample& sample, std::uint8_t counter);
  void advance_health_clock(std::int64_t now_us);
  void publish_health(std::int64_t utime);
  void note_completing_frame(const CanFrame& frame);

  bool rows_seen_ = false;  ///< a CSV row arrived: health uses the CSV full scale

  DaemonConfig config_;
  OutputSink& sink_;
  std::ostream& diagnostics_;
  bool realtime_;
  ProblemLog problems_;
  SampleStream stream_;
  SampleProcessor processor_;
  RunSummary summary_;
  LatencyHistogram latency_window_;
  LatencyHistogram latency_total_;
  std::int64_t samples_ = 0;
  CompletingFrames completing_frames_;
  std::vector<std::uint32_t> wake_ids_;
  std::int64_t last_frame_us_ = 0;  ///< [us] stamp of the last frame or row
  bool have_frame_time_ = false;
  std::int64_t health_window_start_us_ = -1;
  std::int64_t frames_at_window_start_ = 0;
  std::int64_t last_sample_index_ = 0;
  std::uint8_t last_counter_ = 0;
  std::int64_t last_utime_ = 0;  ///< [us] of the last sample
  bool bench_info_seen_ = false;
  std::int64_t kernel_drops_ = 0;
  std::unique_ptr<LiveModelFit> model_fit_;
  RunEstimate run_estimate_;
  SignalHealthLog signal_health_;
  std::function<void(const Sample&)> observer_;
  std::optional<CalibrationTable> table_;  ///< --calibration, re-applied after a reload
  bool have_t_ = false;
  double first_t_ = 0.0;  ///< [s] sample time of the first sample
  double last_t_ = 0.0;   ///< [s] and of the last
  std::vector<Reload> reloads_;
};

}  // namespace resolver
