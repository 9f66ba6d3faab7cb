// The type-II tracking loop against its analytic closed-loop behaviour.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "daemon/core/angles.h"
#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/tracking_loop.h"
#include "tests/unit/effects/chain_test_support.h"

namespace resolver {
namespace {

TrackingLoopParams loop_config(double omega_n, double zeta) { return {{"omega_n", omega_n}, {"zeta", zeta}}; }

/// Independent closed form of |H(j w)| and arg H(j w) for
/// H(s) = (2 zeta wn s + wn^2) / (s^2 + 2 zeta wn s + wn^2).
std::complex<double> analytic_h(double wn, double zeta, double w) {
  const double re_num = wn * wn;
  const double im_num = 2.0 * zeta * wn * w;
  const double re_den = wn * wn - w * w;
  const double im_den = 2.0 * zeta * wn * w;
  const double den = re_den * re_den + im_den * im_den;
  return {(re_num * re_den + im_num * im_den) / den, (im_num * re_den - re_num * im_den) / den};
}

TEST(EffectsTrackingLoop, TheSimulatedLoopIsTheEffectsOneList) {
  // The registry unit, the simulated converter and the fit read one list: no second
  // set of names, ranges or defaults beside it to drift from it.
  EXPECT_EQ(tracking_loop_effect().params().data(), kTrackingLoopParams.data());
  EXPECT_FALSE(tracking_loop_active(TrackingLoopParams{}));  // neutral omega_n = 0: the ideal converter
}

TEST(EffectsTrackingLoop, SubstepsKeepOmegaNStepSmall) {
  const TrackingLoopParams c = loop_config(3000.0, 0.7);
  const int n = tracking_loop_substeps(c, 1.0 / 2000.0);
  EXPECT_GE(n, 1);
  EXPECT_LE(c["omega_n"] * (1.0 / 2000.0) / n, kTrackingLoopMaxOmegaNStep);
  EXPECT_EQ(tracking_loop_substeps(TrackingLoopParams{}, 1.0 / 2000.0), 1);
}

TEST(EffectsTrackingLoop, ConstantSpeedHasZeroSteadyStateError) {
  // Type II: a ramp input is tracked with zero error. Start wrong by 0.2 rad and
  // 20% speed; after 30 loop time constants 1/(zeta wn) the transient is e^-30.
  const double wn = 3000.0;
  const double zeta = 0.7;
  const double speed = 62.8;  // [rad/s] resolver electrical (200 r/min, p_r = 3)
  TrackingLoop loop(loop_config(wn, zeta));
  loop.reset({0.2, 0.8 * speed});
  const auto envelope = [&](double t) { return ideal_envelopes(speed * t); };
  const double period = 1.0 / 2000.0;
  const int settle = static_cast<int>(std::ceil(30.0 / (zeta * wn) / period));
  for (int k = 0; k < settle + 200; ++k) {
    loop.advance(envelope, k * period, period);
    if (k >= settle) {
      const double t_end = (k + 1) * period;
      // At steady state RK4 maps (phi = theta, w = speed) onto itself exactly, so only
      // the transient (e^-30 of 0.2 rad) and rounding of |theta| ~ 10 rad remain.
      ASSERT_NEAR(wrap_pi(speed * t_end - loop.state().phi), 0.0, 1e-10) << k;
      ASSERT_NEAR(loop.state().omega, speed, 1e-7);
    }
  }
}

TEST(EffectsTrackingLoop, ConstantAccelerationLagsByAOverOmegaNSquared) {
  // Under theta = a t^2 / 2 the nonlinear loop settles where w' = wn^2 sin(e) = a,
  // i.e. e = asin(a / wn^2) (linearised: the familiar a / wn^2 acceleration lag).
  const double wn = 3000.0;
  const double zeta = 0.7;
  const double accel = 2e5;  // [rad/s^2]: lag ~0.022 rad, large enough to see
  TrackingLoop loop(loop_config(wn, zeta));
  loop.reset({0.0, 0.0});
  const auto envelope = [&](double t) { return ideal_envelopes(0.5 * accel * t * t); };
  const double period = 1.0 / 2000.0;
  const int n = static_cast<int>(std::ceil(30.0 / (zeta * wn) / period));
  for (int k = 0; k < n; ++k) loop.advance(envelope, k * period, period);
  const double t_end = n * period;
  const double lag = wrap_pi(0.5 * accel * t_end * t_end - loop.state().phi);
  // The forcing is a polynomial of degree 2 in t; RK4's local error on the smooth
  // nonlinear settling is ~(wn h)^5/120 relative, far below 1e-7 rad.
  EXPECT_NEAR(lag, std::asin(accel / (wn * wn)), 1e-7);
  EXPECT_GT(lag, 0.02);  // the lag really is there
}

TEST(EffectsTrackingLoop, LibraryGainAndPhaseMatchClosedForm) {
  const TrackingLoopParams c = loop_config(2500.0, 0.5);
  for (const double w : {10.0, 800.0, 2500.0, 7000.0}) {
    const std::complex<double> h = analytic_h(c["omega_n"], c["zeta"], w);
    EXPECT_NEAR(tracking_loop_gain(c, w), std::abs(h), 1e-12);
    EXPECT_NEAR(tracking_loop_phase(c, w), std::arg(h), 1e-12);
  }
  // At w = wn: H = (1 + 2 zeta j)/(2 zeta j), |H| = sqrt(1 + 4 zeta^2) / (2 zeta) > 1.
  EXPECT_NEAR(tracking_loop_gain(c, c["omega_n"]), std::sqrt(1.0 + 4.0 * 0.25) / 1.0, 1e-12);
}

/// Runs the loop on theta(t) = w0 t + a sin(2 pi f t) and returns the measured
/// complex gain of phi's modulation at f (Fourier coefficient over whole periods).
std::complex<double> measured_gain(const TrackingLoopParams& c, double f, double w0, double a) {
  TrackingLoop loop(c);
  loop.reset({0.0, w0});
  const double wm = kTwoPi * f;
  const auto theta = [&](double t) { return w0 * t + a * std::sin(wm * t); };
  const auto envelope = [&](double t) { return ideal_envelopes(theta(t)); };
  // Settle: 30 loop time constants, rounded up to whole modulation periods.
  const double settle = std::ceil(30.0 / (c["zeta"] * c["omega_n"]) * f) / f;
  const int per_period = 200;
  const double dt = 1.0 / (f * per_period);
  const int settle_steps = static_cast<int>(std::lround(settle / dt));
  double t = 0.0;
  for (int k = 0; k < settle_steps; ++k, t = k * dt) loop.advance(envelope, t, dt);
  std::complex<double> acc = 0.0;
  const int periods = 4;
  for (int k = 0; k < periods * per_period; ++k) {
    const double t0 = (settle_steps + k) * dt;
    loop.advance(envelope, t0, dt);
    const double t1 = t0 + dt;
    const double y = loop.state().phi - w0 * t1;  // the modulation part of phi
    acc += y * std::exp(std::complex<double>(0.0, -wm * t1));
  }
  // y = a |H| sin(wm t + arg H) -> coefficient = a H / (2j) per sample on average.
  const std::complex<double> coef = acc / static_cast<double>(periods * per_period);
  return coef * std::complex<double>(0.0, 2.0) / a;
}

TEST(EffectsTrackingLoop, ClosedLoopGainMatchesAnalyticH) {
  const TrackingLoopParams c = loop_config(3000.0, 0.7);
  const double fn = c["omega_n"] / kTwoPi;
  for (const double ratio : {0.1, 0.5, 1.0, 2.0, 4.0}) {
    const double f = ratio * fn;
    const std::complex<double> h_meas = measured_gain(c, f, 60.0, 1e-3);
    const std::complex<double> h = analytic_h(c["omega_n"], c["zeta"], kTwoPi * f);
    // Linearisation: sin(e) vs e with |e| <= a |1 - H| ~ 2e-3 -> relative error ~e^2/6 ~ 1e-6.
    // RK4 with wm h <= 0.2 per step: phase/gain error ~1e-5. Tolerance 1e-4 covers both.
    EXPECT_NEAR(std::abs(h_meas), std::abs(h), 1e-4 * std::abs(h) + 1e-6) << "f/fn=" << ratio;
    EXPECT_NEAR(std::arg(h_meas), std::arg(h), 1e-4) << "f/fn=" << ratio;
  }
}

TEST(EffectsTrackingLoop, ImbalanceRippleIsFilteredBySpeed) {
  // docs/ARCHITECTURE.md §7: the loop filters the 2theta error of amplitude imbalance: at resolver
  // speed w the ripple is (alpha/2)|H(j 2w)| sin(2theta + arg H(j 2w)).
  const double alpha = 0.002;
  const ForwardChain chain = test::forward_chain(
      {{"amplitude_imbalance", "alpha", alpha}, {"tracking_loop", "omega_n", 3000.0}, {"tracking_loop", "zeta", 0.7}});
  // The converter the registry's tracking_loop hook sets up (what the simulator integrates).
  const TrackingLoopParams c = chain.converter().loop;
  ASSERT_EQ(c["omega_n"], 3000.0);
  for (const double w : {50.0, 1500.0, 4000.0}) {  // |H(j2w)| from ~1 down to ~0.3
    TrackingLoop loop(c);
    loop.reset({0.0, w});
    const auto envelope = [&](double t) { return chain.envelopes(w * t); };
    const double period_2 = kPi / w;  // period of the 2theta ripple [s]
    const int per_period = 400;
    const double dt = period_2 / per_period;
    const int settle = static_cast<int>(std::ceil(30.0 / (c["zeta"] * c["omega_n"]) / period_2)) * per_period;
    for (int k = 0; k < settle; ++k) loop.advance(envelope, k * dt, dt);
    std::complex<double> acc = 0.0;
    for (int k = 0; k < 2 * per_period; ++k) {
      const double t0 = (settle + k) * dt;
      loop.advance(envelope, t0, dt);
      const double theta = w * (t0 + dt);
      acc += wrap_pi(theta - loop.state().phi) * std::exp(std::complex<double>(0.0, -2.0 * theta));
    }
    const std::complex<double> measured = acc / static_cast<double>(2 * per_period) * std::complex<double>(0.0, 2.0);
    const std::complex<double> expected = 0.5 * alpha * analytic_h(c["omega_n"], c["zeta"], 2.0 * w);
    // Omitted: O(alpha^2) terms of the static error (<= ~alpha^2/4 at 2theta, see
    // the signature test) times a gain <= 1.2; integration error ~1e-5 relative.
    EXPECT_NEAR(std::abs(measured - expected), 0.0, 0.5 * 0.002 * 0.002) << "w=" << w;
  }
}

TEST(EffectsTrackingLoop, IdealConverterFollowsStaticAngle) {
  const ForwardChain chain = test::forward_chain({{"amplitude_imbalance", "alpha", 0.01}});
  // The chain's converter without a tracking_loop setting: omega_n = 0, ideal.
  ASSERT_EQ(chain.converter().loop["omega_n"], 0.0);
  TrackingLoop loop(chain.converter().loop);
  const double w = 100.0;
  for (int k = 0; k < 400; ++k) {
    loop.advance([&](double t) { return chain.envelopes(w * t); }, k * 1e-3, 1e-3);
    const double theta = w * (k + 1) * 1e-3;
    ASSERT_NEAR(wrap_pi(loop.angle() - static_rd_angle(chain.envelopes(theta))), 0.0, 1e-12);
    ASSERT_NEAR(loop.state().phi, theta - 0.0, 0.01);  // continuous, not wrapped
  }
}

}  // namespace
}  // namespace resolver
