// Signal-domain compensation: corrected sin/cos -> atan2, Hanselman's
// sum/difference, and the software tracking observer.
//
// Noise floor of an angle read from noisy envelopes: with s = A sin t + n_s,
// c = A cos t + n_c, atan2 moves by (n_s cos t - n_c sin t)/A to first order: the
// tangential component of the 2-D noise, which has std sigma for iid channels.
// So the floor is sigma/A [rad rms] per sample, with sigma = sqrt(sigma_g^2 + 1/12)
// counts for the simulator's i16 samples (Gaussian plus rounding).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "daemon/core/estimation/sincos_compensation.h"
#include "daemon/core/estimation/sincos_least_squares.h"
#include "estimator_test_support.h"

namespace resolver {
namespace {

using test::simulate;

SimConfig imperfect_sim(double seconds) {
  SimConfig cfg;
  cfg.profile = {{seconds, 200.0, 200.0}};
  cfg.chain.set("amplitude_imbalance", "alpha", 0.03);
  cfg.chain.set("quadrature", "beta", 0.01);
  cfg.chain.set("offsets", "o_s", 0.005);
  cfg.chain.set("offsets", "o_c", -0.004);
  return cfg;
}

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

TEST(SinCosCompensation, CorrectedAngleReachesTheNoiseFloor) {
  const SimConfig cfg = imperfect_sim(2.0);
  const auto recs = simulate(cfg);
  const std::size_t half = recs.size() / 2;
  for (bool reference : {true, false}) {
    SinCosLsConfig lc;
    lc.fit_reference_offset = false;
    SinCosLeastSquares ls(lc);
    for (std::size_t i = 0; i < half; ++i) {
      if (reference) {
        ls.add(recs[i].s, recs[i].c, recs[i].theta_ref);
      } else {
        ls.add(recs[i].s, recs[i].c);
      }
    }
    const auto fit = ls.solve();
    ASSERT_TRUE(fit.has_value());
    const SinCosCorrection corr = SinCosCorrection::from_fit(*fit);
    std::vector<double> raw, comp, sumdiff;
    for (std::size_t i = half; i < recs.size(); ++i) {
      const auto& r = recs[i];
      raw.push_back(wrap_pi(r.theta - std::atan2(r.s, r.c)));
      comp.push_back(wrap_pi(r.theta - corrected_angle(corr, r.s, r.c)));
      sumdiff.push_back(wrap_pi(r.theta - sum_difference_angle(corr, r.s, r.c)));
    }
    const double floor = test::sim_sigma(cfg) / cfg.amplitude_counts;
    EXPECT_LT(rms(comp), 1.5 * floor) << (reference ? "reference" : "conic");
    EXPECT_LT(rms(sumdiff), 1.5 * floor) << (reference ? "reference" : "conic");
    EXPECT_GT(rms(raw), 50.0 * floor);
    std::printf("  %s: raw %.3e  corrected %.3e  sum/diff %.3e  floor %.3e rad\n", reference ? "ref  " : "conic",
                rms(raw), rms(comp), rms(sumdiff), floor);
  }
}

TEST(SinCosCompensation, SumDifferenceAndOrthogonalisationAreExactOnCleanSignals) {
  SinCosCorrection corr;
  corr.amplitude = 1000.0;
  corr.alpha = 0.04;
  corr.beta = 0.08;
  corr.o_s = 0.01;
  corr.o_c = -0.02;
  const ForwardChain chain = test::forward_chain({{"amplitude_imbalance", "alpha", corr.alpha},
                                                  {"quadrature", "beta", corr.beta},
                                                  {"offsets", "o_s", corr.o_s},
                                                  {"offsets", "o_c", corr.o_c}});
  for (int k = 0; k < 360; ++k) {
    const double theta = kTwoPi * k / 360.0 + 0.01;
    const SinCos sc = chain.envelopes(theta);
    const double s = corr.amplitude * sc.s, c = corr.amplitude * sc.c;
    EXPECT_NEAR(wrap_pi(theta - corrected_angle(corr, s, c)), 0.0, 1e-12);
    EXPECT_NEAR(wrap_pi(theta - sum_difference_angle(corr, s, c)), 0.0, 1e-12);
  }
}

TEST(SinCosCompensation, HarmonicRemovalLeavesSecondOrderError) {
  SinCosCorrection corr;
  corr.amplitude = 1.0;
  corr.alpha = 0.01;
  corr.orders = {3};
  corr.k = {0.005};
  const ForwardChain chain =
      test::forward_chain({{"amplitude_imbalance", "alpha", corr.alpha}, {"harmonics", "k3", 0.005}});
  double worst = 0.0, worst_raw = 0.0;
  SinCosCorrection no_h = corr;
  no_h.orders.clear();
  no_h.k.clear();
  for (int k = 0; k < 720; ++k) {
    const double theta = kTwoPi * k / 720.0;
    const SinCos sc = chain.envelopes(theta);
    worst = std::max(worst, std::abs(wrap_pi(theta - corrected_angle(corr, sc.s, sc.c))));
    worst_raw = std::max(worst_raw, std::abs(wrap_pi(theta - corrected_angle(no_h, sc.s, sc.c))));
  }
  // One fixed-point step leaves O(K_3 * K_3 * 3) (the first-pass angle error
  // K_3 times the harmonic's slope 3 K_3): < 4 K_3^2 = 1e-4; without it, ~K_3.
  EXPECT_LT(worst, 4.0 * 0.005 * 0.005);
  EXPECT_GT(worst_raw, 0.8 * 0.005);
}

TEST(TrackingObserver, TracksConstantSpeedWithoutLagAndFiltersNoise) {
  SimConfig cfg = imperfect_sim(2.0);
  const auto recs = simulate(cfg);
  SinCosLsConfig lc;
  lc.fit_reference_offset = false;
  SinCosLeastSquares ls(lc);
  for (const auto& r : recs) ls.add(r.s, r.c, r.theta_ref);
  const auto fit = ls.solve();
  ASSERT_TRUE(fit.has_value());
  const SinCosCorrection corr = SinCosCorrection::from_fit(*fit);
  TrackingObserverConfig oc;
  oc.omega_n = 500.0;
  oc.sample_period = 1.0 / cfg.sample_rate_hz;
  TrackingObserver obs(oc);
  std::vector<double> err;
  double mean = 0.0;
  for (std::size_t i = 0; i < recs.size(); ++i) {
    const double phi = obs.update(correct_sincos(corr, recs[i].s, recs[i].c));
    if (i >= recs.size() / 2) {  // after 1 s = 350 / (zeta omega_n) time constants
      err.push_back(wrap_pi(recs[i].theta - phi));
      mean += err.back();
    }
  }
  mean /= static_cast<double>(err.size());
  const double floor = test::sim_sigma(cfg) / cfg.amplitude_counts;
  // The loop averages the per-sample noise (bandwidth ~ omega_n << sample rate),
  // so its rms error is below the static atan2 floor; type II: no mean lag.
  EXPECT_LT(rms(err), floor);
  EXPECT_LT(std::abs(mean), 5.0 * floor / std::sqrt(static_cast<double>(err.size())) + 2e-6);
  EXPECT_NEAR(obs.speed(), kTwoPi * 10.0, 0.01);  // 200 r/min x p_r 3 = 10 rev/s
}

TEST(TrackingObserver, LagUnderAccelerationMatchesTheDesign) {
  const double a = 200.0;  // [rad/s^2] resolver electrical acceleration
  // omega_n h = 0.25 (coarse) and 0.05 (fine) at h = 0.5 ms.
  for (double omega_n : {500.0, 100.0}) {
    TrackingObserverConfig oc;
    oc.omega_n = omega_n;
    oc.zeta = 0.7;
    oc.sample_period = 5e-4;
    TrackingObserver obs(oc);
    double lag = 0.0;
    for (int i = 0; i < 8000; ++i) {  // 4 s = 56 time constants 1/(zeta omega_n) at omega_n = 100
      const double t = i * oc.sample_period;
      const double theta = 0.5 * a * t * t;
      obs.update(ideal_envelopes(theta));
      lag = wrap_pi(theta - obs.angle());
    }
    const double h = oc.sample_period;
    const double wh = omega_n * h;
    // Exact steady state of the discrete loop (header): a h^2 (1 - g) / k.
    const double designed = a * h * h * (1.0 - obs.gain_angle()) / obs.gain_speed();
    EXPECT_NEAR(lag, designed, 1e-3 * designed);
    // The continuous loop's a / omega_n^2, to first order in omega_n h: (1 - g) =
    // exp(-2 zeta omega_n h) and k / (omega_n h)^2 = 1 - O(omega_n h) partly cancel,
    // so the relative deviation is below 2 zeta omega_n h.
    const double continuous = a / (omega_n * omega_n);
    EXPECT_NEAR(lag, continuous, 2.0 * oc.zeta * wh * continuous);
    EXPECT_GT(std::abs(lag - continuous), 0.1 * wh * continuous) << "the discrete loop is not the continuous one";
    std::printf("  omega_n h = %.2f: lag %.4e rad, a/omega_n^2 %.4e rad\n", wh, lag, continuous);
  }
  EXPECT_THROW(TrackingObserver(TrackingObserverConfig{0.0, 0.7, 1e-3}), std::invalid_argument);
}

}  // namespace
}  // namespace resolver
