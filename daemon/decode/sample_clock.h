// The sample clock: one time axis for every input and both programs.
//
// resolverd's estimators and resolver-model's fit read the same `Sample::t`,
// set here from what the input offers:
//
//   counter time   t = (index - anchor index) / sample rate    a counter and a rate exist
//   frame time     t = (stamp - anchor stamp)                   otherwise (or time_source = "frame")
//
// t starts at 0 on the first sample, never goes back, and keeps going across
// a log loop (restart()). Timestamps are not trusted blindly: recordings have
// clocks that step back (a second log appended to the first, an NTP step) or
// jump (+1 day), and a step is not a reason to lose the samples after it.
// Every sample yields a reading; an odd step is an event the caller counts:
//
//   kStepBack  the stamp went back. With a counter that continues, time
//              continues from the counter; else t continues one period after
//              the previous sample (the two pieces are joined end to end).
//              (With counter time and a consecutive counter, a step back of
//              up to kMaxUnexplainedPeriods periods is delivery jitter: the
//              previous sample's frames came late, e.g. a USB adapter's
//              buffering; the counter gives the time, nothing to count.)
//   kJump      the stamp jumped forward by more than kMinJumpSeconds (and
//              kMaxUnexplainedPeriods periods) while the counter says the
//              samples are consecutive: a clock set, or a sender that paused;
//              time continues from the counter. (A shorter lead is a reader or
//              player that stalled and delivers late: the counter already
//              gives the time, nothing to count.) Without a counter
//              only a step beyond kMaxGapSeconds is read as a jump (t continues
//              one period on): shorter silences are real (a recorder pausing).
//   kOutage    the stamp jumped forward and the counter jumped too: samples
//              were lost for longer than a u8 counter can count. t takes the
//              frame-time gap.
//   kGap       no counter: the stamp says more than 1.5 periods passed; the
//              missing samples are counted (samples_lost), `index` skips them
//              and t keeps the gap.
//
// The period is 1 / sample rate where known, else the median stamp spacing of
// the first kPeriodSamples steps. Pure: no I/O, no clocks.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

namespace resolver {

enum class ClockEvent : std::uint8_t { kNone, kStepBack, kJump, kOutage, kGap };

struct ClockReading {
  double t = 0.0;             ///< [s] since the first sample
  std::int64_t index = 0;     ///< sample number: the counter unwrapped, or a running count with gaps skipped
  ClockEvent event = ClockEvent::kNone;
  double step_s = 0.0;        ///< [s] stamp step from the previous sample (for messages)
  std::int64_t index_step = 0;   ///< counter (or count) step from the previous sample
  std::int64_t samples_lost = 0; ///< kGap: samples missing according to time
};

struct SampleClockConfig {
  /// [bench] time_source = "counter": counter time where a counter and a rate exist.
  bool counter_time = true;
  /// [Hz] nominal sample rate; 0 = unknown (learned for gap detection only).
  double sample_rate_hz = 0.0;
  /// A counter step up to this many is "consecutive with some lost" ([layout] max_counter_delta).
  int max_counter_delta = 8;
};

class SampleClock {
 public:
  /// A stamp that runs ahead of what the counter explains by more than this
  /// many periods is a jump, not jitter. The counter is u8: beyond 128 periods
  /// it could have wrapped unseen, so counting cannot bridge such a gap; slow or
  /// bursty delivery (canplayer bursts, emulated replays) stays far below it.
  static constexpr double kMaxUnexplainedPeriods = 128.0;
  /// [s] Without a counter, a longer silence is a clock jump (a second recording
  /// appended, a clock set), not a pause: recorders that pause for seconds exist
  /// (the ServoProject export in tests/data/corpus stops for 1.1 s every 5 s and
  /// once for 7.8 s), benches that log an hour of nothing do not.
  static constexpr double kMaxGapSeconds = 3600.0;
  /// [s] With a consecutive counter, a stamp ahead of it by less than this is
  /// late delivery (canplayer under emulation stalls 70-130 ms, a loaded
  /// reader more), not a clock jump worth a count.
  static constexpr double kMinJumpSeconds = 1.0;
  /// Stamp steps a learned period is the median of.
  static constexpr int kPeriodSamples = 64;

  explicit SampleClock(SampleClockConfig config) : config_(config) {}

  /// Time of the next sample: `stamp_us` [us] its first frame's (or row's)
  /// stamp; `counter_index` the unwrapped counter when the input has one.
  /// Cannot fail.
  ClockReading read(std::int64_t stamp_us, std::optional<std::int64_t> counter_index);

  /// A new nominal rate (BENCH_INFO): time stays continuous, the new rate
  /// applies from the next sample on.
  void set_sample_rate(double hz);
  /// A config reload: the new settings from the next sample on, time and index
  /// continuous. A rate of 0 keeps the one in use (learned, or from BENCH_INFO).
  void reconfigure(const SampleClockConfig& config);
  /// Log loop: the next sample continues one period after the last one, with
  /// the next index, whatever its stamp and counter say.
  void restart() { started_ = false; }

  /// [s] nominal period, else the learned one; 0 while unknown.
  [[nodiscard]] double period_s() const;
  [[nodiscard]] double sample_rate_hz() const { return config_.sample_rate_hz; }
  /// [s] time of the last sample read (0 before the first).
  [[nodiscard]] double last_t() const { return last_t_; }
  /// True when t comes from the counter (a counter and a rate exist).
  [[nodiscard]] bool uses_counter_time() const { return last_counter_time_; }

 private:
  void learn_period(double step_s);
  void anchor(double t, std::int64_t index, std::int64_t stamp_us);

  SampleClockConfig config_;
  bool started_ = false;
  bool ever_started_ = false;
  bool last_counter_time_ = false;
  double last_t_ = 0.0;
  std::int64_t last_index_ = 0;      ///< output index of the previous sample
  std::int64_t last_raw_index_ = 0;  ///< counter index of the previous sample
  std::int64_t last_stamp_us_ = 0;
  double anchor_t_ = 0.0;
  std::int64_t anchor_index_ = 0;
  std::int64_t anchor_stamp_us_ = 0;
  std::array<double, kPeriodSamples> steps_{};
  int step_count_ = 0;
  double learned_period_s_ = 0.0;
};

}  // namespace resolver
