// Every compensable catalog effect, alone on the simulator's default chain:
// simulate, estimate, compensate, and check that the position error of the
// compensated angle falls to within 1.5x the floor set by noise and quantization.
// Fit on the first second, evaluate on the next (out of sample).
//
// The floors (rms position error [rad] of an angle with no systematic error left):
//  - angle from the sampled sin/cos (signal-domain compensation): with
//    s = A sin t + n_s, c = A cos t + n_c, atan2 moves by (n_s cos t - n_c sin t)/A
//    to first order, the tangential component of the two channels' noise; for
//    independent channels of std sigma each that has std sigma for every t, so
//      floor_sc = sigma / A,   sigma = sqrt(sigma_sc^2 + 1/12) counts
//    (the simulator's Gaussian noise plus rounding to i16, uniform over one count).
//    After the correction the cos channel is divided by (1 + alpha) and
//    orthogonalised by 1/cos(beta): the floor changes by O(alpha, beta) only.
//  - R/D angle (angle-domain compensation, theta_c = theta_rd + eps_hat(theta_rd)):
//    the converter rounds its angle to rd_bits, an error uniform over one LSB, so
//      floor_rd^2 = LSB^2 / 12 + (sigma_rd)^2,   LSB = 2pi / 2^rd_bits
//    where sigma_rd is the sin/cos noise reaching the converter's angle. In the
//    simulator the converter demodulates noise-free envelopes (its own analog
//    front end; ADC noise is the DSP's, bench_simulator.h), so sigma_rd = 0 and
//    floor_rd = LSB / sqrt(12).
// The fitted correction adds its own estimation error, ~ floor * sqrt(p / N) for p
// parameters over N fit samples (p <= 13, N = 2000: < 0.1 floor, in quadrature).
//
// alpha vs K_3 from sin/cos data (both put sin 2theta into the R/D error) is
// covered by SinCosLeastSquares.TellsAlphaFromThirdHarmonic in
// test_sincos_least_squares.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "daemon/core/effects/quantization.h"
#include "daemon/core/estimation/angle_error_fourier.h"
#include "daemon/core/estimation/sincos_compensation.h"
#include "daemon/core/estimation/sincos_least_squares.h"
#include "estimator_test_support.h"

namespace resolver {
namespace {

using test::SimRecord;
using test::simulate;

constexpr double kFloorFactor = 1.5;
constexpr double kFitSeconds = 1.0;

/// Default simulator chain with `spec` applied ("effect:param=value,...").
SimConfig with_effect(const std::string& spec, double rpm, int rd_bits = 16) {
  SimConfig cfg;
  cfg.profile = {{2.0 * kFitSeconds, rpm, rpm}};
  cfg.rd_bits = rd_bits;
  cfg.theta_m0 = 0.37;  // [rad] any start angle; not a quantization-friendly one
  EXPECT_NO_THROW(cfg.chain.apply_spec(spec));
  return cfg;
}

double floor_sincos(const SimConfig& cfg) { return test::sim_sigma(cfg) / cfg.amplitude_counts; }
double floor_rd(const SimConfig& cfg) { return quantization_lsb(cfg.rd_bits) / std::sqrt(12.0); }

struct Rms {
  double raw = 0.0;
  double comp = 0.0;
};

/// Signal domain: sin/cos LS against the reference on the fit second, then the
/// corrected atan2 on the evaluation second, both against the true angle.
Rms sincos_compensation(const std::vector<SimRecord>& recs, const SinCosLsConfig& lc) {
  SinCosLeastSquares ls(lc);
  std::size_t i = 0;
  for (; i < recs.size() && recs[i].t < kFitSeconds; ++i) ls.add(recs[i].s, recs[i].c, recs[i].theta_ref);
  const auto fit = ls.solve_reference();
  EXPECT_TRUE(fit.has_value());
  if (!fit) return {};
  const SinCosCorrection corr = SinCosCorrection::from_fit(*fit);
  double raw2 = 0.0, comp2 = 0.0;
  const std::size_t first = i;
  for (; i < recs.size(); ++i) {
    const SimRecord& r = recs[i];
    raw2 += std::pow(wrap_pi(r.theta - std::atan2(r.s, r.c)), 2);
    comp2 += std::pow(wrap_pi(r.theta - corrected_angle(corr, r.s, r.c)), 2);
  }
  const double n = static_cast<double>(recs.size() - first);
  return {std::sqrt(raw2 / n), std::sqrt(comp2 / n)};
}

/// Angle domain: Fourier fit of eps = theta_ref - theta_rd, then
/// theta_rd + eps_hat(theta_rd), against the true angle.
Rms fourier_compensation(const std::vector<SimRecord>& recs) {
  AngleFourierConfig fc;
  fc.max_order = 6;
  AngleErrorFourier af(fc);
  std::size_t i = 0;
  for (; i < recs.size() && recs[i].t < kFitSeconds; ++i) af.add(recs[i].theta_ref, recs[i].rd);
  const auto fit = af.solve();
  EXPECT_TRUE(fit.has_value());
  if (!fit) return {};
  double raw2 = 0.0, comp2 = 0.0;
  const std::size_t first = i;
  for (; i < recs.size(); ++i) {
    const SimRecord& r = recs[i];
    raw2 += std::pow(wrap_pi(r.theta - r.rd), 2);
    comp2 += std::pow(wrap_pi(r.theta - fit->compensate(r.rd)), 2);
  }
  const double n = static_cast<double>(recs.size() - first);
  return {std::sqrt(raw2 / n), std::sqrt(comp2 / n)};
}

SinCosLsConfig aligned_ls(std::vector<int> harmonics = {}) {
  SinCosLsConfig lc;
  lc.fit_reference_offset = false;  // the simulator's encoder is aligned with the resolver
  lc.harmonics = std::move(harmonics);
  return lc;
}

void expect_at_floor(const char* what, const Rms& e, double floor) {
  std::printf("  %-44s raw %.3e  compensated %.3e  floor %.3e rad (%.2fx)\n", what, e.raw, e.comp, floor,
              e.comp / floor);
  EXPECT_LT(e.comp, kFloorFactor * floor) << what;
  EXPECT_GT(e.raw, 10.0 * floor) << what << ": the effect must be well above the floor for the test to mean anything";
}

TEST(CompensationFloor, AmplitudeImbalance) {
  const SimConfig cfg = with_effect("amplitude_imbalance:alpha=0.03", 200.0);
  const auto recs = simulate(cfg);
  expect_at_floor("amplitude_imbalance, sin/cos LS", sincos_compensation(recs, aligned_ls()), floor_sincos(cfg));
  expect_at_floor("amplitude_imbalance, Fourier (R/D, 16 bit)", fourier_compensation(recs), floor_rd(cfg));
}

// A 12-bit converter: quantization (4.4e-4 rad rms) is then the R/D floor by far.
TEST(CompensationFloor, AmplitudeImbalanceTwelveBitConverter) {
  const SimConfig cfg = with_effect("amplitude_imbalance:alpha=0.03", 200.0, 12);
  const auto recs = simulate(cfg);
  expect_at_floor("amplitude_imbalance, Fourier (R/D, 12 bit)", fourier_compensation(recs), floor_rd(cfg));
}

TEST(CompensationFloor, Quadrature) {
  const SimConfig cfg = with_effect("quadrature:beta=0.01", 200.0);
  const auto recs = simulate(cfg);
  expect_at_floor("quadrature, sin/cos LS", sincos_compensation(recs, aligned_ls()), floor_sincos(cfg));
  expect_at_floor("quadrature, Fourier (R/D)", fourier_compensation(recs), floor_rd(cfg));
}

TEST(CompensationFloor, Offsets) {
  const SimConfig cfg = with_effect("offsets:o_s=0.005,o_c=-0.004", 200.0);
  const auto recs = simulate(cfg);
  expect_at_floor("offsets, sin/cos LS", sincos_compensation(recs, aligned_ls()), floor_sincos(cfg));
  expect_at_floor("offsets, Fourier (R/D)", fourier_compensation(recs), floor_rd(cfg));
}

// K_0 lands in the fitted offsets (sincos_least_squares.h); K_3 needs the
// harmonic in the LS model. The correction's single fixed-point step leaves
// ~3 K_3^2 = 1.2e-5 rad (sincos_compensation.h), well below the floor.
TEST(CompensationFloor, HarmonicsK0AndK3) {
  const SimConfig cfg = with_effect("harmonics:k0=0.001,k3=0.002", 200.0);
  const auto recs = simulate(cfg);
  expect_at_floor("harmonics k0 + k3, sin/cos LS with n = 3", sincos_compensation(recs, aligned_ls({3})),
                  floor_sincos(cfg));
  expect_at_floor("harmonics k0 + k3, Fourier (R/D)", fourier_compensation(recs), floor_rd(cfg));
  // Without the harmonic in the model the 3theta terms stay in the corrected angle.
  const Rms plain = sincos_compensation(recs, aligned_ls());
  EXPECT_GT(plain.comp, 5.0 * floor_sincos(cfg));
}

// Sampling skew at one speed: at 1000 r/min (p_r = 3, omega = 314 rad/s) a skew of
// 20 us is an equivalent quadrature beta = omega tau = 6.3e-3 rad on the DSP's
// samples (sampling_skew.h), which the reference fit estimates as beta and the
// orthogonalisation removes. The R/D angle does not carry it (the converter does
// not see the DSP's sampling), so there is nothing to compensate there.
TEST(CompensationFloor, SamplingSkewAtOneSpeed) {
  const SimConfig cfg = with_effect("sampling_skew:tau=2e-5", 1000.0);
  const auto recs = simulate(cfg);
  expect_at_floor("sampling_skew at 1000 r/min, sin/cos LS", sincos_compensation(recs, aligned_ls()),
                  floor_sincos(cfg));
  SinCosLeastSquares ls(aligned_ls());
  for (const SimRecord& r : recs) ls.add(r.s, r.c, r.theta_ref);
  const auto fit = ls.solve_reference();
  ASSERT_TRUE(fit.has_value());
  const double omega = 1000.0 / 60.0 * kTwoPi * cfg.p_r;  // [rad/s] resolver electrical
  EXPECT_NEAR(fit->beta.value, omega * 2e-5, 5.0 * fit->beta.std_error + 1e-6);
}

}  // namespace
}  // namespace resolver
