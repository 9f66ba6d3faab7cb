#include "daemon/decode/sample_clock.h"

#include <algorithm>
#include <cmath>

namespace resolver {

namespace {
// A learned period is trusted from this many stamp steps on (fewer: unknown).
constexpr int kMinStepsForPeriod = 8;
// Without a counter, a step longer than this many periods means samples are missing.
constexpr double kGapPeriods = 1.5;
}  // namespace

double SampleClock::period_s() const {
  return config_.sample_rate_hz > 0.0 ? 1.0 / config_.sample_rate_hz : learned_period_s_;
}

void SampleClock::set_sample_rate(double hz) {
  if (!(hz > 0.0) || hz == config_.sample_rate_hz) return;
  config_.sample_rate_hz = hz;
  // Counter time from here on, counted from the last sample: t stays continuous.
  anchor(last_t_, last_index_, last_stamp_us_);
}

void SampleClock::reconfigure(const SampleClockConfig& config) {
  const double rate = config.sample_rate_hz > 0.0 ? config.sample_rate_hz : config_.sample_rate_hz;
  config_ = config;
  config_.sample_rate_hz = rate;
  anchor(last_t_, last_index_, last_stamp_us_);
}

void SampleClock::anchor(double t, std::int64_t index, std::int64_t stamp_us) {
  anchor_t_ = t;
  anchor_index_ = index;
  anchor_stamp_us_ = stamp_us;
}

void SampleClock::learn_period(double step_s) {
  if (step_count_ >= kPeriodSamples || !(step_s > 0.0)) return;
  steps_[static_cast<std::size_t>(step_count_++)] = step_s;
  if (step_count_ < kMinStepsForPeriod) return;
  std::array<double, kPeriodSamples> sorted = steps_;
  const auto n = static_cast<std::ptrdiff_t>(step_count_);
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.begin() + n);
  learned_period_s_ = sorted[static_cast<std::size_t>(n / 2)];
}

ClockReading SampleClock::read(std::int64_t stamp_us, std::optional<std::int64_t> counter_index) {
  ClockReading r;
  const bool counter_time = config_.counter_time && counter_index.has_value() && config_.sample_rate_hz > 0.0;
  const double period = period_s();
  if (!started_) {
    // The first sample, or the first after a log loop (one period after the last).
    if (ever_started_) {
      r.index = last_index_ + 1;
      r.t = last_t_ + period;
    } else {
      r.index = counter_index.value_or(0);
    }
    started_ = ever_started_ = true;
    anchor(r.t, r.index, stamp_us);
  } else {
    r.step_s = static_cast<double>(stamp_us - last_stamp_us_) / 1e6;
    r.index_step = counter_index ? std::max<std::int64_t>(1, *counter_index - last_raw_index_) : 1;
    const bool consecutive = !counter_index || r.index_step <= config_.max_counter_delta;
    const double expected_s = static_cast<double>(r.index_step) * period;
    if (r.step_s < 0.0) {
      // A stamp a little behind the previous one while the counter goes on and sets
      // the time: the previous sample's frames came late (an adapter's buffering), no event.
      const bool delivery_jitter =
          counter_time && consecutive && -r.step_s <= kMaxUnexplainedPeriods * period;
      if (!delivery_jitter) r.event = ClockEvent::kStepBack;
    } else if (!counter_index) {
      if (r.step_s > kMaxGapSeconds) {
        r.event = ClockEvent::kJump;
      } else if (period > 0.0 && r.step_s > kGapPeriods * period) {
        r.samples_lost = std::llround(r.step_s / period) - 1;
        if (r.samples_lost > 0) r.event = ClockEvent::kGap;
      }
    } else if (period > 0.0 && r.step_s - expected_s > kMaxUnexplainedPeriods * period) {
      if (!consecutive) {
        r.event = ClockEvent::kOutage;
      } else if (r.step_s - expected_s > kMinJumpSeconds) {
        r.event = ClockEvent::kJump;
      }
    }
    r.index = last_index_ + r.index_step + r.samples_lost;
    const double frame_t = anchor_t_ + static_cast<double>(stamp_us - anchor_stamp_us_) / 1e6;
    switch (r.event) {
      case ClockEvent::kNone:
      case ClockEvent::kGap:
        r.t = counter_time ? anchor_t_ + static_cast<double>(r.index - anchor_index_) / config_.sample_rate_hz : frame_t;
        break;
      case ClockEvent::kStepBack:
      case ClockEvent::kJump:
        if (counter_time && consecutive) {
          // The counter says how much time passed; the stamp is what is wrong.
          r.t = anchor_t_ + static_cast<double>(r.index - anchor_index_) / config_.sample_rate_hz;
        } else {
          // Nothing says how much time passed: the pieces join end to end.
          r.t = last_t_ + static_cast<double>(consecutive ? r.index_step : 1) * period;
          anchor(r.t, r.index, stamp_us);
        }
        break;
      case ClockEvent::kOutage:
        // Frame time keeps the gap; counter time restarts counting after it.
        r.t = last_t_ + r.step_s;
        anchor(r.t, r.index, stamp_us);
        break;
    }
    if (r.event == ClockEvent::kNone && r.step_s > 0.0) {
      learn_period(r.step_s / static_cast<double>(r.index_step));
    }
  }
  last_t_ = r.t;
  last_index_ = r.index;
  last_raw_index_ = counter_index.value_or(r.index);
  last_stamp_us_ = stamp_us;
  last_counter_time_ = counter_time;
  return r;
}

}  // namespace resolver
