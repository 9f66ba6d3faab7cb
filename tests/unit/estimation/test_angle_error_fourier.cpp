// Angle-domain Fourier fit of the R/D position error (Hanselman III.A) on the
// bench simulator's R/D angle, with and without the reference encoder.
//
// Noise: the simulator's R/D angle is computed from noise-free envelopes and
// quantized to 16 bits, so eps carries uniform noise of LSB/sqrt(12) = 2.8e-5 rad;
// a Fourier coefficient over N samples then has std 2.8e-5 sqrt(2/N) (the
// reported std_error, checked below). The catalog mapping is first order: the
// omitted terms are products of two parameters, bounded here by
// (|alpha| + |beta| + |o_s| + |o_c|)^2, which dominates the tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "daemon/core/estimation/angle_error_fourier.h"
#include "estimator_test_support.h"

namespace resolver {
namespace {

using test::simulate;

SimConfig fourier_sim(double seconds, double rpm0, double rpm1) {
  SimConfig cfg;
  cfg.profile = {{seconds, rpm0, rpm1}};
  cfg.chain.set("amplitude_imbalance", "alpha", 0.01);
  cfg.chain.set("quadrature", "beta", 0.004);
  cfg.chain.set("offsets", "o_s", 0.002);
  cfg.chain.set("offsets", "o_c", -0.003);
  return cfg;
}

double second_order(const ChainValues& ch) {
  const double sum = std::abs(ch.get("amplitude_imbalance", "alpha")) + std::abs(ch.get("quadrature", "beta")) +
                     std::abs(ch.get("offsets", "o_s")) + std::abs(ch.get("offsets", "o_c"));
  return sum * sum;
}

constexpr double kQuantSigma = 9.587379924285257e-05 / 3.4641016151377544;  // 2pi/2^16 / sqrt(12) [rad]

TEST(AngleErrorFourier, ReferenceFitMapsToCatalogParameters) {
  SimConfig cfg = fourier_sim(1.0, 200.0, 200.0);
  const auto recs = simulate(cfg);
  AngleErrorFourier f(AngleFourierConfig{});
  for (const auto& r : recs) f.add(r.theta_ref, r.rd);
  const auto fit = f.solve();
  ASSERT_TRUE(fit.has_value());
  const double so = second_order(cfg.chain);
  const auto& ch = cfg.chain;
  EXPECT_NEAR(fit->alpha.value, ch.get("amplitude_imbalance", "alpha"), so);
  EXPECT_NEAR(fit->beta.value, ch.get("quadrature", "beta"), so);
  EXPECT_NEAR(fit->o_s.value, ch.get("offsets", "o_s"), so);
  EXPECT_NEAR(fit->o_c.value, ch.get("offsets", "o_c"), so);
  // Constant: -beta/2 (Hanselman 7, sign of effects/quadrature.h).
  EXPECT_NEAR(fit->a0.value, -0.5 * ch.get("quadrature", "beta"), so);
  // Coefficient std errors: the quantization floor sqrt(2/N) (x 1.3 for the
  // tracking loop's few-LSB dither and the O(1/N) non-uniformity).
  const double se = kQuantSigma * std::sqrt(2.0 / static_cast<double>(recs.size()));
  EXPECT_LT(fit->a[2].std_error, 1.3 * se);
  EXPECT_GT(fit->a[2].std_error, 0.5 * se);
  std::printf("  ref: alpha %.6f beta %.6f o_s %.6f o_c %.6f  se(a2) %.2e  resid %.2e\n", fit->alpha.value,
              fit->beta.value, fit->o_s.value, fit->o_c.value, fit->a[2].std_error, fit->residual_rms);
}

TEST(AngleErrorFourier, CompensationRemovesTheErrorDownToTheResidualHarmonics) {
  const SimConfig cfg = fourier_sim(2.0, 200.0, 200.0);
  const auto recs = simulate(cfg);
  AngleFourierConfig fc;
  fc.max_order = 6;
  AngleErrorFourier f(fc);
  const std::size_t half = recs.size() / 2;
  for (std::size_t i = 0; i < half; ++i) f.add(recs[i].theta_ref, recs[i].rd);
  const auto fit = f.solve();
  ASSERT_TRUE(fit.has_value());
  double raw2 = 0.0, comp2 = 0.0;
  for (std::size_t i = half; i < recs.size(); ++i) {
    raw2 += std::pow(wrap_pi(recs[i].theta_ref - recs[i].rd), 2);
    comp2 += std::pow(wrap_pi(recs[i].theta_ref - fit->compensate(recs[i].rd)), 2);
  }
  const double n = static_cast<double>(recs.size() - half);
  const double raw = std::sqrt(raw2 / n), comp = std::sqrt(comp2 / n);
  // Floor: quantization, plus the fit's own error (13 coefficients x se) and the
  // converter's residual dither: 1.5 x the quantization sigma.
  EXPECT_LT(comp, 1.5 * kQuantSigma);
  EXPECT_GT(raw, 50.0 * comp);
  std::printf("  eps rms raw %.3e rad, compensated %.3e rad (quantization %.3e)\n", raw, comp, kQuantSigma);
}

// Without a reference: the ideal angle is a polynomial in time fitted jointly
// with the harmonics. Under a speed ramp (200 -> 260 r/min in 2 s) a quadratic
// describes the true angle exactly; a line does not, and its misfit leaks into
// the harmonics.
TEST(AngleErrorFourier, SmoothIdealAngleFitUnderAcceleration) {
  SimConfig cfg = fourier_sim(2.0, 200.0, 260.0);
  cfg.chain.set("quadrature", "beta", 0.0);  // its constant part is not identifiable without reference
  const auto recs = simulate(cfg);
  std::vector<double> t, rd;
  for (const auto& r : recs) {
    t.push_back(r.t);
    rd.push_back(r.rd);
  }
  AngleFourierConfig fc;
  const auto fit = fit_error_smooth_angle(t, rd, fc);
  ASSERT_TRUE(fit.has_value());
  EXPECT_GE(fit->revolutions, 22.0);  // 2 s at 10..13 rev/s
  const double so = second_order(cfg.chain);
  EXPECT_NEAR(fit->alpha.value, cfg.chain.get("amplitude_imbalance", "alpha"), so);
  EXPECT_NEAR(fit->beta.value, 0.0, so);
  EXPECT_NEAR(fit->o_s.value, cfg.chain.get("offsets", "o_s"), so);
  EXPECT_NEAR(fit->o_c.value, cfg.chain.get("offsets", "o_c"), so);
  // The tracking loop's acceleration lag a/omega_n^2 is constant: the polynomial takes it.
  EXPECT_LT(fit->residual_rms, 2.0 * kQuantSigma);

  AngleFourierConfig line = fc;
  line.poly_order = 1;
  const auto bad = fit_error_smooth_angle(t, rd, line);
  ASSERT_TRUE(bad.has_value());
  EXPECT_GT(bad->residual_rms, 10.0 * fit->residual_rms);
  std::printf("  no-ref: alpha %.6f o_s %.6f o_c %.6f resid %.2e (line: %.2e)\n", fit->alpha.value, fit->o_s.value,
              fit->o_c.value, fit->residual_rms, bad->residual_rms);
}

TEST(AngleErrorFourier, LargeAlphaUsesTheExactInversion) {
  // alpha = 5 %: the sin 2theta coefficient is a_2 = alpha/(2 + alpha), so the first-order
  // 2 a_2 is low by ~alpha^2/2 = 1.25e-3 (2.5 % relative); the exact inversion
  // 2 a_2/(1 - a_2) leaves only the quantization noise.
  SimConfig cfg;
  cfg.profile = {{1.0, 200.0, 200.0}};
  cfg.chain.set("tracking_loop", "omega_n", 0.0);  // ideal converter: eps is exactly the static error
  cfg.chain.set("amplitude_imbalance", "alpha", 0.05);
  const auto recs = simulate(cfg);
  AngleErrorFourier f(AngleFourierConfig{});
  for (const auto& r : recs) f.add(r.theta_ref, r.rd);
  const auto fit = f.solve();
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->alpha.value, 0.05, 5.0 * fit->alpha.std_error + 1e-6);
  EXPECT_GT(std::abs(2.0 * fit->a[2].value - 0.05), 10.0 * fit->alpha.std_error);
}

TEST(AngleErrorFourier, RefusesShortWindowsAndBadConfig) {
  std::vector<double> t{0.0, 0.1, 0.2}, th{0.0, 0.1, 0.2};
  EXPECT_FALSE(fit_error_smooth_angle(t, th, AngleFourierConfig{}).has_value());
  AngleErrorFourier f(AngleFourierConfig{});
  EXPECT_FALSE(f.solve().has_value());
  AngleFourierConfig bad;
  bad.max_order = 0;
  EXPECT_THROW(AngleErrorFourier{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace resolver
