// The quantum of a channel, as the noise floor needs it (noise_floor.h).
#include "daemon/core/discovery/noise_floor.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/core/angles.h"

namespace resolver {
namespace {

constexpr double kLsb = kTwoPi / 65536.0;  // a 16-bit R/D converter [rad]

TEST(ChannelQuantum, QuantizedRampGivesTheLsb) {
  // 0.36 deg per sample is 65.536 LSB: steps of 65 and 66 codes, one LSB apart.
  std::vector<double> v;
  for (int i = 0; i < 2000; ++i) v.push_back(std::floor(i * 65.536) * kLsb);
  EXPECT_NEAR(channel_quantum(v), kLsb, 1e-12);
}

TEST(ChannelQuantum, OneStepSizeIsMotionNotAQuantizer) {
  // A commanded or perfectly smooth reference at a speed commensurate with the sample
  // rate steps by the same amount every sample (and holds still between): that step
  // is the motion. The moteus sweep's commanded angle and a scope's encoder column do this.
  std::vector<double> v(300, 0.0);
  for (int i = 1; i <= 1000; ++i) v.push_back(i * 0.36 * kPi / 180.0);
  for (int i = 0; i < 300; ++i) v.push_back(v.back());
  EXPECT_EQ(channel_quantum(v), 0.0);
}

TEST(ChannelQuantum, ContinuousSignalHasNone) {
  std::vector<double> v;
  for (int i = 0; i < 2000; ++i) v.push_back(std::sin(0.01 * i) + 1e-3 * std::sin(1.7 * i * i));
  EXPECT_LT(channel_quantum(v), 1e-6);
}

TEST(StandstillFloor, TheConvertersRingingAfterAStopIsNotTheSensorsNoise) {
  // A 10 kHz log that stops abruptly from 600 r/min (p_r = 3) and holds 2 s: the R/D
  // loop (omega_n = 3000 rad/s, zeta = 0.7) rings down from ~omega / omega_n = 0.06 rad
  // in the first milliseconds of the standstill; the sensor's noise is 3e-5 rad.
  constexpr double kDt = 1e-4, kSigma = 3e-5, kOmega = 600.0 / 60.0 * kTwoPi * 3.0, kWn = 3000.0, kZeta = 0.7;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::vector<FitRow> rows(20000);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double t = static_cast<double>(i) * kDt;
    const double wd = kWn * std::sqrt(1.0 - kZeta * kZeta);
    rows[i].flags = FitRow::kHasRd;  // not moving: the whole stretch is standstill
    rows[i].y_rd = kOmega / kWn * std::exp(-kZeta * kWn * t) * std::sin(wd * t) + noise(rng);
  }
  // Control: the ringing is far above the noise over the whole stretch, so a floor
  // that took it in would fail the check below by a wide margin.
  double ss = 0.0, sum = 0.0;
  for (const FitRow& r : rows) {
    sum += r.y_rd;
    ss += r.y_rd * r.y_rd;
  }
  const double n = static_cast<double>(rows.size());
  ASSERT_GT(std::sqrt(ss / n - sum * sum / (n * n)), 5.0 * kSigma);

  const FloorReport f = estimate_floors(rows, kDt, true, ChannelQuanta{}, true);
  EXPECT_EQ(f.rd.source, "standstill");
  EXPECT_EQ(f.rd.standstill_samples, 19000);  // the first 0.1 s of the stretch is left to settle
  // 19000 samples: the sample standard deviation's relative standard error is
  // 1 / sqrt(2 N) = 0.5 %; 3 % is six of them.
  EXPECT_NEAR(f.rd.chosen, kSigma, 0.03 * kSigma);
}

/// Sample standard deviation of the R/D signal over rows [from, end).
double rd_deviation(const std::vector<FitRow>& rows, std::size_t from) {
  double sum = 0.0, ss = 0.0;
  for (std::size_t i = from; i < rows.size(); ++i) {
    sum += rows[i].y_rd;
    ss += rows[i].y_rd * rows[i].y_rd;
  }
  const double n = static_cast<double>(rows.size() - from);
  return std::sqrt(ss / n - sum * sum / (n * n));
}

TEST(StandstillFloor, ARingingLongerThanTheFixedGuardIsWaitedOut) {
  // A 10 kHz log's 3 s stop on a bench whose coupling between resolver and reference has
  // a lightly damped 20 Hz mode (zeta = 0.05, decay time 0.16 s): the position error
  // rings from 1 mrad, far longer than the fixed 0.1 s guard. The sensor's noise is 3e-5 rad.
  constexpr double kDt = 1e-4, kSigma = 3e-5, kF = 20.0, kZeta = 0.05, kA = 1e-3;
  const double wn = kTwoPi * kF;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::vector<FitRow> rows(30000);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double t = static_cast<double>(i) * kDt;
    rows[i].flags = FitRow::kHasRd;
    rows[i].y_rd = kA * std::exp(-kZeta * wn * t) * std::cos(wn * t) + noise(rng);
  }
  // Control: after the fixed guard alone the ringing still makes the deviation 2x the noise.
  ASSERT_GT(rd_deviation(rows, 1000), 2.0 * kSigma);
  const FloorReport f = estimate_floors(rows, kDt, true, ChannelQuanta{}, true);
  EXPECT_EQ(f.rd.source, "standstill");
  // What is kept starts once a 10 ms block's mean square is within 1.5x the noise's
  // variance (ringing amplitude ~3e-5, after ~0.5 s); what rings on beyond adds ~1.6 % of
  // the variance (0.8 % of the deviation). With ~25000 samples the estimate's own
  // standard error is 0.45 %: 3 % is that bias and four of them.
  EXPECT_NEAR(f.rd.chosen, kSigma, 0.03 * kSigma);
  EXPECT_LT(f.rd.standstill_samples, 26000);
  EXPECT_GT(f.rd.standstill_samples, 20000) << "waited for longer than the ringing lasts";
}

TEST(StandstillFloor, NoiseAloneIsNotMistakenForSettling) {
  // Control of the above: a 3 s stop of white noise keeps everything after the fixed guard.
  constexpr double kDt = 1e-4, kSigma = 3e-5;
  std::mt19937 rng(12);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::vector<FitRow> rows(30000);
  for (FitRow& r : rows) {
    r.flags = FitRow::kHasRd;
    r.y_rd = noise(rng);
  }
  const FloorReport f = estimate_floors(rows, kDt, true, ChannelQuanta{}, true);
  EXPECT_EQ(f.rd.standstill_samples, 29000);
  EXPECT_NEAR(f.rd.chosen, kSigma, 0.03 * kSigma);  // 0.4 % standard error: 3 %
}

}  // namespace
}  // namespace resolver
