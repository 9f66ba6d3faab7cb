#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "daemon/core/angles.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/quantization.h"

namespace resolver {
namespace {

TEST(EffectsQuantization, ErrorIsUniformWithinHalfLsb) {
  for (const int bits : {10, 12, 14, 16}) {
    const double lsb = quantization_lsb(bits);
    const int n = 200000;
    double max_err = 0.0;
    double sum_sq = 0.0;
    for (int i = 0; i < n; ++i) {
      // Golden-ratio stepping spreads the grid evenly over the LSB cells.
      const double phi = kTwoPi * std::fmod(i * 0.6180339887498949, 1.0);
      const std::uint16_t counts = quantize_rd_angle(phi, bits);
      ASSERT_EQ(counts % (1U << (16 - bits)), 0U) << "low bits must be zero";
      const double err = wrap_pi(phi - rd_counts_to_angle(counts));
      max_err = std::max(max_err, std::abs(err));
      sum_sq += err * err;
    }
    EXPECT_LE(max_err, 0.5 * lsb * (1.0 + 1e-9)) << bits;
    // Rounding of a uniformly spread angle: RMS = LSB/sqrt(12). With 2e5 evenly spread
    // points the empirical RMS is within ~1e-3 relative; 1% tolerance.
    EXPECT_NEAR(std::sqrt(sum_sq / n), lsb / std::sqrt(12.0), 0.01 * lsb / std::sqrt(12.0)) << bits;
  }
}

TEST(EffectsQuantization, WrapsAndRoundsAtTheEnds) {
  const double lsb12 = quantization_lsb(12);
  EXPECT_EQ(quantize_rd_angle(kTwoPi - 0.1 * lsb12, 12), 0U);  // rounds up to 2pi == 0
  EXPECT_EQ(quantize_rd_angle(-0.1 * lsb12, 12), 0U);
  EXPECT_EQ(quantize_rd_angle(0.6 * lsb12, 12), 16U);  // one 12-bit LSB is 16 u16 counts
  EXPECT_EQ(quantize_rd_angle(kPi, 16), 32768U);
  EXPECT_EQ(quantize_rd_angle(kPi + 5 * kTwoPi, 16), 32768U);
  EXPECT_DOUBLE_EQ(rd_counts_to_angle(16384), 0.5 * kPi);
}

TEST(EffectsNoise, GaussianHasTheRequestedSigma) {
  NoiseEngine engine(42);
  const double sigma = 2.5;
  const int n = 200000;
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = gaussian_noise(engine, sigma);
    sum += x;
    sum_sq += x * x;
  }
  const double mean = sum / n;
  const double sd = std::sqrt(sum_sq / n - mean * mean);
  // 5-sigma statistical bounds: mean sd sigma/sqrt(n), sample-sd sd ~ sigma/sqrt(2n).
  EXPECT_NEAR(mean, 0.0, 5.0 * sigma / std::sqrt(n));
  EXPECT_NEAR(sd, sigma, 5.0 * sigma / std::sqrt(2.0 * n));
}

TEST(EffectsNoise, ZeroSigmaLeavesTheEngineAlone) {
  NoiseEngine a(7);
  NoiseEngine b(7);
  EXPECT_EQ(gaussian_noise(a, 0.0), 0.0);
  EXPECT_EQ(a, b);
  EXPECT_EQ(gaussian_noise(a, 1.0), gaussian_noise(b, 1.0));  // same seed, same draw
}

}  // namespace
}  // namespace resolver
