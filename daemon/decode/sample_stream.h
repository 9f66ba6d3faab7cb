// Input to samples: the one path from frames (candump, ASC, SocketCAN) or rows
// (CSV / scope exports) to resolver::Sample, shared by resolverd's Pipeline and
// resolver-model's log reader, so both see the same samples at the same times.
//
//   CanFrame  ─► FrameIntake (DBC, units, CRC, counters, join) ─┐
//   RowSample ─► FrameIntake::feed_sample (counted as one frame) ┴► BenchSample
//        └► SampleClock (t, index; odd time counted) ─► slice ─► to_sample() ─► on_sample
//   BENCH_INFO ─► its sample rate to the clock ([bench] use_bench_info) ─► on_bench_info
//
// Odd time is never a reason to lose samples: a stamp that steps back or
// jumps is counted (timestamp_step_back, timestamp_jump, sample_clock_reanchored)
// and the clock re-anchors (sample_clock.h); without a counter, gaps found from
// time are counted (sample_gap, samples_lost). Rows with a time column wait in a
// window of max_counter_delta rows and go on in time order: a row that comes
// before one it follows in time (two rows swapped) is counted as rows_reordered,
// naming both lines, never as a step back and a gap. Pure: no I/O.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/sample.h"
#include "daemon/decode/frame_intake.h"
#include "daemon/decode/row_sample.h"
#include "daemon/decode/sample_clock.h"
#include "daemon/decode/sample_slice.h"

namespace resolver {

struct SampleStreamConfig {
  SampleClockConfig clock;
  bool use_bench_info = true;  ///< BENCH_INFO's sample rate replaces clock.sample_rate_hz
  /// [Hz] rate of rows without a time column ([input.csv] row_rate_hz).
  double row_rate_hz = 0.0;
  SampleSlice slice;
};

/// The one conversion of a joined sample to what the estimators read: signals
/// present only when complete (sin and cos, all three currents), time and
/// index from the sample clock, utime the sample's first frame [us].
[[nodiscard]] Sample to_sample(const BenchSample& joined, const ClockReading& clock);

class SampleStream {
 public:
  struct Callbacks {
    /// Each sample inside the slice; `counter` is the u8 counter (or index & 0xFF).
    std::function<void(const Sample&, std::uint8_t counter)> on_sample;
    std::function<void(const BenchInfo&)> on_bench_info;
    /// reason (a counter name) and a one-line message.
    std::function<void(std::string_view reason, const std::string& message)> on_problem;
  };

  SampleStream(std::shared_ptr<const FrameDecoder> decoder, const SampleStreamConfig& config, Callbacks callbacks);

  /// One frame; `line` its log line (0 live). Cannot fail.
  void feed(const CanFrame& frame, std::uint64_t line = 0) {
    line_ = line;
    intake_.feed(frame, line);
  }
  /// One decoded row (CSV); `line` its line in the file. Cannot fail.
  void feed_row(const RowSample& row, std::uint64_t line = 0);
  /// Counts a problem found before decoding (a malformed line or row).
  void count_problem(std::string_view reason, const std::string& message) { intake_.count_problem(reason, message); }
  /// End of input: the rows waiting and the open sample.
  void flush() {
    release_rows();
    intake_.flush();
  }
  /// Log loop: counters and joins restart; time and index continue.
  void restart_sequence();
  /// A config reload: `config` (its slice is ignored: the command line's stays) and,
  /// when `decoder` is set, a new layout (FrameIntake::change_decoder). Time, sample
  /// index, statistics and rejects continue. Cannot fail.
  void reconfigure(std::shared_ptr<const FrameDecoder> decoder, const SampleStreamConfig& config);

  /// True once a sample was later than the slice's end: reading further is useless.
  [[nodiscard]] bool past_slice_end() const { return past_slice_end_; }
  [[nodiscard]] std::int64_t samples_outside_slice() const { return outside_slice_; }
  [[nodiscard]] const SampleSlice& slice() const { return config_.slice; }
  [[nodiscard]] const FrameIntake& intake() const { return intake_; }
  [[nodiscard]] const SampleClock& clock() const { return clock_; }

 private:
  void on_joined(const BenchSample& joined);
  /// A row on to the intake (line_ its line).
  void pass_row(const RowSample& row, std::uint64_t line);
  /// Passes every row waiting in the reorder window on, in time order.
  void release_rows();
  void report_clock_event(const BenchSample& joined, const ClockReading& r);

  SampleStreamConfig config_;
  Callbacks callbacks_;
  FrameIntake intake_;
  SampleClock clock_;
  std::uint64_t line_ = 0;  ///< line of the frame or row being fed (messages)
  bool past_slice_end_ = false;
  std::int64_t outside_slice_ = 0;
  /// Timed rows waiting for a row that belongs before them, sorted by time.
  struct WaitingRow {
    RowSample row;
    std::uint64_t line = 0;
  };
  std::vector<WaitingRow> waiting_rows_;
  bool row_passed_ = false;           ///< a timed row went on (its time in last_row_us_)
  std::int64_t last_row_us_ = 0;
};

}  // namespace resolver
