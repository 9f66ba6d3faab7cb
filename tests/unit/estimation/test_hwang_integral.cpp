// Hwang integral estimator on synthetic R/D angles.
//
// The R/D angle with amplitude imbalance is generated from the exact
// steady-state of an ideal tracking converter (error signal
// sin(theta) cos(phi) - (1+alpha) cos(theta) sin(phi) = 0), i.e.
//   phi = atan2(sin theta, (1+alpha) cos theta),
// not from the small-angle formula the estimator assumes. Its sin(2 theta)
// Fourier coefficient is q = alpha / (2 + alpha), so the estimator's value,
// 2q, differs from alpha by alpha^2/2 relative: the approximation error of
// Hwang eq. 10, which the tolerances below include.
#include <gtest/gtest.h>

#include <cmath>

#include "daemon/core/angles.h"
#include "daemon/core/estimation/hwang_integral.h"

namespace resolver {
namespace {

struct RotationCase {
  double alpha = 0.003;
  double beta = 0.0;
  double offset_sin = 0.0;
  double omega = kTwoPi * 10.0;   // [rad/s] resolver electrical: 200 r/min x 3 pole pairs
  double rate = 2000.0;           // [Hz]
  int rd_bits = 16;
  double seconds = 3.0;
};

// Exact R/D angle for amplitude imbalance, quadrature and a sin offset.
double rd_angle(const RotationCase& s, double theta) {
  const double sn = std::sin(theta) + s.offset_sin;
  const double cs = (1.0 + s.alpha) * std::cos(theta + s.beta);
  const double phi = wrap_2pi(std::atan2(sn, cs));
  const double lsb = kTwoPi / std::ldexp(1.0, s.rd_bits);
  return wrap_2pi(std::round(phi / lsb) * lsb);
}

HwangIntegralEstimator run(const RotationCase& s, double theta0 = 0.3) {
  HwangIntegralEstimator est(HwangIntegralConfig{});
  const int n = static_cast<int>(s.seconds * s.rate);
  for (int i = 0; i < n; ++i) {
    const double t = i / s.rate;
    est.update(t, rd_angle(s, theta0 + s.omega * t));
  }
  return est;
}

// Per-revolution std of alpha from R/D quantization (uniform, LSB^2/12 per
// sample): alpha_k = 2 sum(s eps) / sum(s sin 2theta) with sum(s sin 2theta)
// ~ N 2/pi, so sigma = pi LSB / sqrt(12 N).
double quantization_sigma(const RotationCase& s) {
  const double lsb = kTwoPi / std::ldexp(1.0, s.rd_bits);
  const double n = s.rate * kTwoPi / std::abs(s.omega);
  return kPi * lsb / std::sqrt(12.0 * n);
}

TEST(HwangIntegral, RecoversAlphaAtHwangsOperatingPoint) {
  const RotationCase s;
  const auto est = run(s);
  ASSERT_TRUE(est.converged());
  EXPECT_GE(est.revolutions(), 25);  // 3 s at 10 rev/s, minus the partial first/last
  const double approx = s.alpha * s.alpha / 2.0;  // Hwang eq. 10 approximation error (relative)
  const double tol = s.alpha * approx + 5.0 * quantization_sigma(s);
  EXPECT_NEAR(est.alpha(), s.alpha, tol);
  EXPECT_LT(est.alpha_spread(), 5.0 * quantization_sigma(s));
}

TEST(HwangIntegral, LargeImbalanceFollowsExactFourierCoefficient) {
  RotationCase s;
  s.alpha = 0.05;
  const auto est = run(s);
  const double q = s.alpha / (2.0 + s.alpha);  // exact sin(2 theta) coefficient
  // Quarter-sign weighting also sees the 6 theta harmonic (amplitude q^3/3, weight 1/3): bound it.
  const double tol = 2.0 * q * q * q / 9.0 + 5.0 * quantization_sigma(s);
  EXPECT_NEAR(est.alpha(), 2.0 * q, tol);
  EXPECT_GT(std::abs(est.alpha() - s.alpha), 0.5 * s.alpha * s.alpha / 2.0)
      << "the small-angle bias alpha^2/2 should be visible at alpha = 5 %";
}

TEST(HwangIntegral, BlindToQuadratureAndOffsets) {
  // Quadrature gives (beta/2)(1 - cos 2theta) and offsets give 1x terms
  // (Hanselman 7, 9): their quarter areas cancel in Area-0 minus Area-1.
  RotationCase s;
  s.alpha = 0.0;
  s.beta = 0.004;
  s.offset_sin = 0.002;
  const auto est = run(s);
  // Residual coupling is second order: beta * offset and beta^2 terms.
  const double tol = 2.0 * (s.beta * s.beta + s.beta * s.offset_sin) + 5.0 * quantization_sigma(s);
  EXPECT_NEAR(est.alpha(), 0.0, tol);
}

TEST(HwangIntegral, WorksInReverse) {
  RotationCase s;
  s.omega = -s.omega;
  const auto est = run(s);
  ASSERT_TRUE(est.converged());
  EXPECT_NEAR(est.alpha(), s.alpha, s.alpha * s.alpha / 2.0 + 5.0 * quantization_sigma(s));
}

TEST(HwangIntegral, RejectsRevolutionsWhenSpeedChanges) {
  HwangIntegralEstimator est(HwangIntegralConfig{});
  RotationCase s;
  double theta = 0.0;
  const double rate = 2000.0;
  for (int i = 0; i < 6000; ++i) {
    const double t = i / rate;
    // Speed doubles after 1 s: the revolution spanning the step differs by > 2 %.
    const double omega = t < 1.0 ? s.omega : 2.0 * s.omega;
    theta += omega / rate;
    est.update(t, rd_angle(s, theta));
  }
  EXPECT_GE(est.rejected(HwangRejection::kSpeedNotConstant), 1);
  EXPECT_NEAR(est.alpha(), s.alpha, s.alpha * s.alpha / 2.0 + 5.0 * quantization_sigma(s));
}

TEST(HwangIntegral, RevolutionsWithLostSamplesAreRejected) {
  // Frames lost on the bus (kernel drops): every 7th revolution loses a block of
  // 40 of its ~200 samples. Those revolutions must be rejected, not averaged in;
  // the estimate stays within the quantization bound of the clean ones.
  HwangIntegralEstimator est(HwangIntegralConfig{});
  RotationCase s;
  const double rate = 2000.0;
  int dropped_blocks = 0;
  for (int i = 0; i < 40000; ++i) {
    const double t = i / rate;
    const double theta = s.omega * t;
    const auto rev = static_cast<int>(theta / kTwoPi);
    const double in_rev = theta / kTwoPi - rev;
    if (rev % 7 == 3 && in_rev > 0.3 && in_rev < 0.5) {
      if (in_rev + s.omega / rate / kTwoPi >= 0.5) ++dropped_blocks;
      continue;
    }
    est.update(t, rd_angle(s, theta));
  }
  ASSERT_GT(dropped_blocks, 5);
  EXPECT_GE(est.rejected(HwangRejection::kGap), dropped_blocks - 1);
  EXPECT_TRUE(est.converged());
  EXPECT_NEAR(est.alpha(), s.alpha, s.alpha * s.alpha / 2.0 + 5.0 * quantization_sigma(s));
}

TEST(HwangIntegral, TooFewSamplesPerRevolutionAreRejected) {
  RotationCase s;
  s.omega = kTwoPi * 200.0;  // 10 samples per revolution at 2 kHz
  const auto est = run(s);
  EXPECT_EQ(est.revolutions(), 0);
  EXPECT_GT(est.rejected(HwangRejection::kTooFewSamples), 0);
  EXPECT_FALSE(est.converged());
}

TEST(AmplitudeImbalanceEps, MatchesHwangEq10) {
  EXPECT_DOUBLE_EQ(amplitude_imbalance_eps(0.004, kPi / 4.0), 0.002);
  EXPECT_NEAR(amplitude_imbalance_eps(0.004, kPi / 2.0), 0.0, 1e-18);
}

}  // namespace
}  // namespace resolver
