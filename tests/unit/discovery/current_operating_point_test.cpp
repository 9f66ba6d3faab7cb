// The currents' operating point under the current-side effects' ripple (current_operating_point.h).
#include "daemon/core/discovery/current_operating_point.h"

#include <cmath>

#include <gtest/gtest.h>

#include "daemon/core/angles.h"

namespace resolver {
namespace {

// A steady 10 A q current with a 2x theta_e ripple of 0.8 A (a 15 % sensor gain error,
// current_gain_mismatch.h), a 1x one of 0.15 A (sensor offsets) and a 6x one of 0.05 A.
double ripple_d(double th) { return 0.8 * std::cos(2 * th + 0.4) + 0.15 * std::sin(th) + 0.05 * std::cos(6 * th); }
double ripple_q(double th) { return -0.8 * std::sin(2 * th + 0.4) + 0.15 * std::cos(th) - 0.05 * std::sin(6 * th); }

TEST(CurrentOperatingPoint, UnevenCoverageLeaksTheRippleIntoTheMeanButNotIntoTheFit) {
  // Ten electrical turns, then a slow crawl over a quarter turn (a reversal's pass through
  // zero speed) with as many samples: the mean takes a share of the ripple.
  CurrentOperatingPointFit fit;
  double mean_d = 0.0, mean_q = 0.0;
  int n = 0;
  const auto add = [&](double th) {
    fit.add(th, -0.5 + ripple_d(th), 10.0 + ripple_q(th));
    mean_d += -0.5 + ripple_d(th);
    mean_q += 10.0 + ripple_q(th);
    ++n;
  };
  for (int i = 0; i < 2000; ++i) add(10.0 * kTwoPi * i / 2000.0);
  for (int i = 0; i < 2000; ++i) add(0.3 + 0.25 * kPi * i / 2000.0);
  const CurrentOperatingPoint op = fit.result();
  ASSERT_TRUE(op.ripple_separated);
  // Noise-free: the fit is exact to rounding.
  EXPECT_NEAR(op.i_d, -0.5, 1e-9);
  EXPECT_NEAR(op.i_q, 10.0, 1e-9);
  // The control: the mean is off by a good part of the ripple's amplitude.
  EXPECT_GT(std::hypot(mean_d / n + 0.5, mean_q / n - 10.0), 0.1);
}

TEST(CurrentOperatingPoint, TooLittleOfATurnFallsBackToTheMean) {
  // A tenth of a turn cannot tell a 1x ripple from the constant: the plain mean, said so.
  CurrentOperatingPointFit fit;
  double sum_q = 0.0;
  for (int i = 0; i < 500; ++i) {
    const double th = 0.1 * kTwoPi * i / 500.0;
    fit.add(th, ripple_d(th), 10.0 + ripple_q(th));
    sum_q += 10.0 + ripple_q(th);
  }
  const CurrentOperatingPoint op = fit.result();
  EXPECT_FALSE(op.ripple_separated);
  EXPECT_DOUBLE_EQ(op.i_q, sum_q / 500.0);
}

TEST(CurrentOperatingPoint, NoSamplesIsZeroAndNotSeparated) {
  const CurrentOperatingPoint op = CurrentOperatingPointFit{}.result();
  EXPECT_FALSE(op.ripple_separated);
  EXPECT_EQ(op.i_d, 0.0);
  EXPECT_EQ(op.i_q, 0.0);
}

}  // namespace
}  // namespace resolver
