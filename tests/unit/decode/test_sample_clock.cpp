// The sample clock (daemon/decode/sample_clock.h): counter time where a counter
// and a rate exist, frame time otherwise, and odd stamps (a step back, a jump,
// an outage, a gap) counted and re-anchored so no sample is lost and t never
// goes back.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <vector>

#include "daemon/decode/sample_clock.h"

namespace resolver {
namespace {

constexpr double kRate = 2000.0;             // [Hz] the bench's sample rate
constexpr std::int64_t kPeriodUs = 500;      // [us] 1 / kRate
constexpr std::int64_t kT0 = 1'700'000'000'000'000;  // [us] an epoch stamp
// Counter time is an exact multiple of the period: a few ulps of t at t < 1e3 s.
constexpr double kExact = 1e-12;

SampleClock counter_clock() { return SampleClock(SampleClockConfig{true, kRate, 8}); }

TEST(SampleClock, CounterTimeStartsAtZeroAndIgnoresJitter) {
  SampleClock clock = counter_clock();
  // Frames delivered in 1 ms bursts (canplayer, USB adapters): stamps jitter, the counter does not.
  for (std::int64_t k = 0; k < 100; ++k) {
    const std::int64_t stamp = kT0 + (kPeriodUs * k) / 1000 * 1000;
    const ClockReading r = clock.read(stamp, 17 + k);
    EXPECT_EQ(r.event, ClockEvent::kNone) << k;
    EXPECT_EQ(r.index, 17 + k);
    EXPECT_NEAR(r.t, static_cast<double>(k) / kRate, kExact) << k;
  }
  EXPECT_TRUE(clock.uses_counter_time());
}

TEST(SampleClock, StepBackWithAContinuingCounterKeepsCounterTime) {
  SampleClock clock = counter_clock();
  for (std::int64_t k = 0; k < 10; ++k) EXPECT_EQ(clock.read(kT0 + kPeriodUs * k, k).event, ClockEvent::kNone);
  // Issue 16: the stamps step back 1 s in the middle of the log; the counter goes on.
  const std::int64_t back = 1'000'000;
  const ClockReading r = clock.read(kT0 + kPeriodUs * 10 - back, 10);
  EXPECT_EQ(r.event, ClockEvent::kStepBack);
  EXPECT_NEAR(r.step_s, -1.0 + 1.0 / kRate, 1e-9);
  EXPECT_NEAR(r.t, 10.0 / kRate, kExact);
  for (std::int64_t k = 11; k < 20; ++k) {
    const ClockReading after = clock.read(kT0 + kPeriodUs * k - back, k);
    EXPECT_EQ(after.event, ClockEvent::kNone);
    EXPECT_NEAR(after.t, static_cast<double>(k) / kRate, kExact);
  }
}

TEST(SampleClock, JumpWithAConsecutiveCounterIsAClockJump) {
  SampleClock clock = counter_clock();
  for (std::int64_t k = 0; k < 10; ++k) clock.read(kT0 + kPeriodUs * k, k);
  const std::int64_t day = 86'400'000'000;
  const ClockReading r = clock.read(kT0 + kPeriodUs * 10 + day, 10);
  EXPECT_EQ(r.event, ClockEvent::kJump);
  EXPECT_NEAR(r.t, 10.0 / kRate, kExact);  // not a day later: speeds stay right
  EXPECT_NEAR(clock.read(kT0 + kPeriodUs * 11 + day, 11).t, 11.0 / kRate, kExact);
}

TEST(SampleClock, LateDeliveryWithAConsecutiveCounterIsNoEvent) {
  // A player or reader that stalls 100 ms (200 periods) delivers late; the
  // counter says the samples are consecutive and sets the time.
  SampleClock clock = counter_clock();
  for (std::int64_t k = 0; k < 10; ++k) clock.read(kT0 + kPeriodUs * k, k);
  const ClockReading r = clock.read(kT0 + kPeriodUs * 10 + 100'000, 10);
  EXPECT_EQ(r.event, ClockEvent::kNone);
  EXPECT_NEAR(r.t, 10.0 / kRate, kExact);
}

TEST(SampleClock, JumpWithACounterThatJumpedTooIsAnOutage) {
  SampleClock clock = counter_clock();
  for (std::int64_t k = 0; k < 10; ++k) clock.read(kT0 + kPeriodUs * k, k);
  // 2 s without frames and the counter 100 further (it wrapped unseen): frame time keeps the gap.
  const ClockReading r = clock.read(kT0 + kPeriodUs * 9 + 2'000'000, 109);
  EXPECT_EQ(r.event, ClockEvent::kOutage);
  EXPECT_NEAR(r.t, 9.0 / kRate + 2.0, 1e-9);
  const ClockReading next = clock.read(kT0 + kPeriodUs * 10 + 2'000'000, 110);
  EXPECT_EQ(next.event, ClockEvent::kNone);
  EXPECT_NEAR(next.t, r.t + 1.0 / kRate, 1e-9);
}

TEST(SampleClock, AppendedLogJoinsEndToEnd) {
  // Two recordings concatenated: the second starts at the first's start time
  // with its own counter. The pieces join one period apart; t never goes back.
  SampleClock clock = counter_clock();
  double last = 0.0;
  for (std::int64_t k = 0; k < 300; ++k) last = clock.read(kT0 + kPeriodUs * k, k).t;
  const ClockReading r = clock.read(kT0, 300 + 129);  // counter 43 after 171: resynchronised by +129
  EXPECT_EQ(r.event, ClockEvent::kStepBack);
  EXPECT_NEAR(r.t, last + 1.0 / kRate, kExact);
  EXPECT_NEAR(clock.read(kT0 + kPeriodUs, 300 + 130).t, last + 2.0 / kRate, kExact);
}

TEST(SampleClock, WithoutACounterGapsAreFoundFromTime) {
  SampleClock clock(SampleClockConfig{true, kRate, 8});
  std::int64_t stamp = kT0;
  for (int k = 0; k < 10; ++k, stamp += kPeriodUs) EXPECT_EQ(clock.read(stamp, std::nullopt).index, k);
  EXPECT_FALSE(clock.uses_counter_time());
  // Three samples missing: the stamp steps 4 periods.
  stamp += 3 * kPeriodUs;
  const ClockReading r = clock.read(stamp, std::nullopt);
  EXPECT_EQ(r.event, ClockEvent::kGap);
  EXPECT_EQ(r.samples_lost, 3);
  EXPECT_EQ(r.index, 13);
  EXPECT_NEAR(r.t, 13.0 / kRate, 1e-9);
  // Jitter of a third of a period is no gap.
  EXPECT_EQ(clock.read(stamp + kPeriodUs + kPeriodUs / 3, std::nullopt).event, ClockEvent::kNone);
}

TEST(SampleClock, WithoutACounterAJumpOrAStepBackJoinsOnePeriodOn) {
  SampleClock clock(SampleClockConfig{true, 0.0, 8});  // rate unknown: learned from the stamps
  std::int64_t stamp = kT0;
  double t = 0.0;
  for (int k = 0; k < 40; ++k, stamp += 10'000) t = clock.read(stamp, std::nullopt).t;  // 100 Hz scope export
  EXPECT_NEAR(clock.period_s(), 0.01, 1e-12);
  const ClockReading jump = clock.read(stamp + 86'400'000'000, std::nullopt);
  EXPECT_EQ(jump.event, ClockEvent::kJump);
  EXPECT_NEAR(jump.t, t + 0.01, 1e-9);
  const ClockReading back = clock.read(stamp - 5'000'000, std::nullopt);
  EXPECT_EQ(back.event, ClockEvent::kStepBack);
  EXPECT_NEAR(back.t, t + 0.02, 1e-9);
  EXPECT_EQ(back.index, jump.index + 1);
}

TEST(SampleClock, WithoutACounterARecorderPauseIsAGapNotAJump) {
  // The ServoProject export (tests/data/corpus) pauses 7.8 s once: the servo
  // kept turning, so time must keep the pause; only the samples are missing.
  SampleClock clock(SampleClockConfig{true, 0.0, 8});
  std::int64_t stamp = 0;
  ClockReading r;
  for (int k = 0; k < 40; ++k, stamp += 4200) r = clock.read(stamp, std::nullopt);
  const double before = r.t;
  r = clock.read(stamp + 7'777'200 - 4200, std::nullopt);
  EXPECT_EQ(r.event, ClockEvent::kGap);
  EXPECT_NEAR(r.t - before, 7.7772, 1e-9);
  EXPECT_EQ(r.samples_lost, 1851);  // 7.7772 s / 4.2 ms = 1851.7 periods: 1851 rows missing
}

TEST(SampleClock, FrameTimeWhenAsked) {
  SampleClock clock(SampleClockConfig{false, kRate, 8});  // [bench] time_source = "frame"
  clock.read(kT0, 0);
  const ClockReading r = clock.read(kT0 + 730, 1);
  EXPECT_NEAR(r.t, 730e-6, 1e-12);
  EXPECT_FALSE(clock.uses_counter_time());
}

TEST(SampleClock, RateFromBenchInfoKeepsTimeContinuous) {
  SampleClock clock(SampleClockConfig{true, 0.0, 8});
  clock.read(kT0, 0);
  clock.read(kT0 + 510, 1);  // frame time until the rate is known
  clock.set_sample_rate(kRate);
  const ClockReading r = clock.read(kT0 + 990, 2);
  EXPECT_NEAR(r.t, 510e-6 + 1.0 / kRate, 1e-12);  // counter time from the last sample on
  EXPECT_TRUE(clock.uses_counter_time());
}

TEST(SampleClock, LogLoopContinuesTimeAndIndex) {
  SampleClock clock = counter_clock();
  ClockReading last;
  for (std::int64_t k = 0; k < 50; ++k) last = clock.read(kT0 + kPeriodUs * k, k);
  clock.restart();
  const ClockReading r = clock.read(kT0, 0);  // the same log again
  EXPECT_EQ(r.event, ClockEvent::kNone);
  EXPECT_EQ(r.index, last.index + 1);
  EXPECT_NEAR(r.t, last.t + 1.0 / kRate, kExact);
  EXPECT_NEAR(clock.read(kT0 + kPeriodUs, 1).t, last.t + 2.0 / kRate, kExact);
}

}  // namespace
}  // namespace resolver
