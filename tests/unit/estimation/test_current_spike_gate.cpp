// The live dq ripple's spike gate (current_spike_gate.h): white noise and a steady ripple
// pass untouched, spikes alone and in bursts do not, a load step and a gap in time start
// the line again.
#include "daemon/core/estimation/current_spike_gate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace resolver {
namespace {

constexpr double kDt = 5e-4;     // [s] a 2 kHz bench
constexpr double kSigma = 0.02;  // [A] resolver-sim's current noise

/// i_d, i_q of a bench at 30 Hz electrical with a 0.5 A ripple at 2x and noise.
struct Bench {
  std::mt19937_64 engine{5};
  std::normal_distribution<double> noise{0.0, kSigma};
  double d(double t) { return 0.5 * std::cos(2.0 * 2.0 * M_PI * 30.0 * t) + noise(engine); }
  double q(double t) { return 10.0 + 0.5 * std::sin(2.0 * 2.0 * M_PI * 30.0 * t) + noise(engine); }
};

TEST(CurrentSpikeGate, NoiseAndRipplePassUntouched) {
  CurrentSpikeGate gate;
  Bench b;
  for (int i = 0; i < 200000; ++i) {
    const double t = i * kDt;
    ASSERT_TRUE(gate.pass(t, b.d(t), b.q(t))) << i;
  }
  EXPECT_EQ(gate.rejected(), 0);
}

TEST(CurrentSpikeGate, SpikesAloneAndInBurstsAreCaughtAndTheLineStandsIn) {
  CurrentSpikeGate gate;
  Bench b;
  int caught = 0;
  for (int i = 0; i < 20000; ++i) {
    const double t = i * kDt;
    const double d = b.d(t), q = b.q(t);
    const bool spike = i % 500 == 250 || (i % 500 >= 400 && i % 500 < 403);  // one, then three in a row
    const bool passed = gate.pass(t, d + (spike ? 6.7 : 0.0), q + (spike ? -3.0 : 0.0));
    ASSERT_EQ(passed, !spike) << i;
    if (!passed) {
      ++caught;
      // The stand-in is the line through two good samples, r = 1-3 sample periods back:
      // its noise is sigma sqrt((1 + r)^2 + r^2) <= 5 sigma = 0.1 A, the 2x ripple's curvature
      // adds 0.5 A (2 w dt)^2 r^2 / 2 <= 0.16 A; four of the one and the other: 0.6 A, a
      // tenth of the spike it replaces.
      EXPECT_NEAR(gate.line().d, d, 0.6) << i;
      EXPECT_NEAR(gate.line().q, q, 0.6) << i;
    }
  }
  EXPECT_EQ(gate.rejected(), caught);
  EXPECT_EQ(caught, 40 * 4);
}

TEST(CurrentSpikeGate, ALoadStepIsANewLevelNotSpikes) {
  CurrentSpikeGate gate;
  Bench b;
  int rejected_after_step = 0;
  for (int i = 0; i < 4000; ++i) {
    const double t = i * kDt;
    const double q = b.q(t) + (i >= 2000 ? 10.0 : 0.0);  // i_q 10 -> 20 A
    if (!gate.pass(t, b.d(t), q)) ++rejected_after_step;
  }
  // The step's first kMaxRun samples are taken as spikes; then the line starts again.
  EXPECT_EQ(rejected_after_step, CurrentSpikeGate::kMaxRun);
}

TEST(CurrentSpikeGate, AGapInTimeStartsTheLineAgain) {
  CurrentSpikeGate gate;
  Bench b;
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(gate.pass(i * kDt, b.d(i * kDt), b.q(i * kDt)));
  // 50 ms of lost frames, the currents elsewhere on their ripple: not a spike.
  for (int i = 1100; i < 2000; ++i) ASSERT_TRUE(gate.pass(i * kDt, b.d(i * kDt), b.q(i * kDt) + 0.3)) << i;
  EXPECT_EQ(gate.rejected(), 0);
}

}  // namespace
}  // namespace resolver
