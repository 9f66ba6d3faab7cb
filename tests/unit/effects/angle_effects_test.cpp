// The angle-domain effects added in catalog v2: sampling skew, eccentricity and
// mounting offset. Each forward model (the registry's forward chain,
// forward_chain.h) against its signature within a bound derived for that effect,
// and each compensation against the forward model.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "daemon/core/angles.h"
#include "daemon/core/effects/eccentricity.h"
#include "daemon/core/effects/mounting_offset.h"
#include "daemon/core/effects/quadrature.h"
#include "daemon/core/effects/sampling_skew.h"
#include "tests/unit/effects/chain_test_support.h"

namespace resolver {
namespace {

using test::forward_chain;

constexpr int kGrid = 3600;  // theta grid over one turn

/// The quadrature signature's remainder bound (QuadratureMatchesHanselmanEq7 in signatures_test).
double quadrature_bound(double beta) { return test::quadrature_remainder_bound(beta); }

/// The pair the DSP samples (bench_simulator.h): the sin channel of the chain's
/// envelopes at the sample instant's angle, the cos channel at the angle of the
/// instant timing().dsp_cos_dt later.
SinCos dsp_sample(const ForwardChain& chain, double theta_at_sin, double theta_at_cos) {
  return {chain.envelopes(theta_at_sin).s, chain.envelopes(theta_at_cos).c};
}

TEST(EffectsSamplingSkew, ConstantSpeedIsExactlyQuadratureWithBetaOmegaTau) {
  const SamplingSkewParams skew{{"tau", 2e-5}};  // [s]
  const ForwardChain skewed = forward_chain({{"sampling_skew", "tau", skew["tau"]}});
  // The skew is the DSP's: its cos sample is tau late, the converter's input is not.
  ASSERT_EQ(skewed.timing().dsp_cos_dt, skew["tau"]);
  ASSERT_EQ(skewed.timing().converter_cos_dt, 0.0);
  // Two resolver electrical speeds [rad/s]: 3 pole pairs at ~1000 and ~3000 r/min.
  double amplitude_slow = 0.0;
  double amplitude_fast = 0.0;
  for (const double omega : {314.0, 942.0}) {
    const double beta = omega * skew["tau"];
    const ForwardChain quad = forward_chain({{"quadrature", "beta", beta}});
    EXPECT_DOUBLE_EQ(sampling_skew_beta(skew, omega), beta);
    double max_residual = 0.0;
    double max_signature = 0.0;
    for (int i = 0; i < kGrid; ++i) {
      const double t = (i + 0.37) / (kGrid * omega) * kTwoPi;  // [s] one electrical turn
      const double theta = omega * t;
      const SinCos s = dsp_sample(skewed, theta, omega * (t + skewed.timing().dsp_cos_dt));
      const SinCos q = quad.envelopes(theta);
      // theta(t + tau) = theta + omega tau exactly at constant speed: equal up to rounding.
      ASSERT_NEAR(s.s, q.s, 1e-15);
      ASSERT_NEAR(s.c, q.c, 1e-12);
      const double eps = wrap_pi(theta - static_rd_angle(s));
      const double sig = sampling_skew_error(skew, theta, omega);
      EXPECT_DOUBLE_EQ(sig, quadrature_error({{"beta", beta}}, theta));
      max_residual = std::max(max_residual, std::abs(eps - sig));
      max_signature = std::max(max_signature, std::abs(sig));
    }
    // Omitted terms are O(beta^2) (quadrature bound); far below the signature.
    EXPECT_LE(max_residual, quadrature_bound(beta) + 1e-12) << omega;
    EXPECT_LT(quadrature_bound(beta), 0.05 * max_signature) << omega;
    (omega < 500.0 ? amplitude_slow : amplitude_fast) = max_signature;
  }
  // Grows linearly with speed: the peak error is beta = omega tau.
  EXPECT_NEAR(amplitude_fast / amplitude_slow, 942.0 / 314.0, 1e-6);
  // At standstill there is nothing.
  EXPECT_EQ(sampling_skew_error(skew, 0.7, 0.0), 0.0);
}

TEST(EffectsSamplingSkew, UnderAccelerationDiffersFromQuadratureByTauSquared) {
  const double tau = 5e-5;  // [s]
  const ForwardChain skewed = forward_chain({{"sampling_skew", "tau", tau}});
  const double omega0 = 300.0;  // [rad/s]
  const double accel = 2e4;     // [rad/s^2] resolver electrical: a hard speed ramp
  double max_diff = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    const double t = 0.05 * i / kGrid;  // [s]
    const double theta = omega0 * t + 0.5 * accel * t * t;
    const double omega = omega0 + accel * t;
    const double theta_later = omega0 * (t + tau) + 0.5 * accel * (t + tau) * (t + tau);
    const SinCos s = dsp_sample(skewed, theta, theta_later);
    const double beta = sampling_skew_beta({{"tau", tau}}, omega);
    const SinCos q = forward_chain({{"quadrature", "beta", beta}}).envelopes(theta);
    max_diff = std::max(max_diff, std::abs(s.c - q.c));
  }
  // theta(t + tau) - (theta + omega(t) tau) = a tau^2 / 2 and cos is 1-Lipschitz.
  const double bound = 0.5 * accel * tau * tau;
  EXPECT_LE(max_diff, bound * (1.0 + 1e-9) + 1e-15);
  EXPECT_GT(max_diff, 0.5 * bound) << "the second-order term is really there";
}

TEST(EffectsSamplingSkew, CompensationRestoresTheAngle) {
  const SamplingSkewParams skew{{"tau", 2e-5}};  // [s]
  const ForwardChain chain = forward_chain({{"sampling_skew", "tau", skew["tau"]}});
  const double omega = 942.0;
  double max_left = 0.0;
  for (int i = 0; i < 360; ++i) {
    const double theta = kTwoPi * (i + 0.5) / 360.0;
    const SinCos sampled = dsp_sample(chain, theta, theta + omega * chain.timing().dsp_cos_dt);
    // Exact speed: exact fundamental, rounding only.
    EXPECT_NEAR(wrap_pi(theta - static_rd_angle(compensate_sampling_skew(skew, sampled, omega))),
                0.0, 1e-12);
    // A 1 % speed error leaves c' = cos(theta) cos(beta)/cos(beta') + sin(theta) (sin beta' - sin beta)/cos beta':
    // a quadrature-like error of d_beta = beta' - beta (peak d_beta, plus its own O(d_beta^2) remainder) and a
    // gain error cos(beta)/cos(beta') - 1 <= beta d_beta (peak eps beta d_beta / 2).
    const double beta = omega * skew["tau"];
    const double d_beta = 0.01 * beta;
    const double left = wrap_pi(theta - static_rd_angle(compensate_sampling_skew(skew, sampled, 1.01 * omega)));
    EXPECT_LE(std::abs(left), d_beta * (1.0 + beta) + quadrature_bound(d_beta));
    max_left = std::max(max_left, std::abs(left));
  }
  EXPECT_GT(max_left, 0.9 * 0.01 * omega * skew["tau"]) << "a wrong speed must leave an error";
}

TEST(EffectsEccentricity, IsAOneTimesMechanicalError) {
  const EccentricityParams ecc{{"e", 1e-3}, {"phase", 0.7}};
  const int p_r = 3;
  ForwardChain chain =
      forward_chain({{"eccentricity", "e", ecc["e"]}, {"eccentricity", "phase", ecc["phase"]}}, p_r, 3);
  // Through the whole envelope path and an ideal converter: eps = p_r eps_m exactly.
  double c1 = 0.0;
  double s1 = 0.0;
  double c_pr = 0.0;
  double s_pr = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    const double theta_m = kTwoPi * i / kGrid;
    const double seen = chain.resolver_angle(theta_m, 1.0, true);
    const double eps = wrap_pi(p_r * theta_m - static_rd_angle(chain.envelopes(seen)));
    ASSERT_NEAR(eps, p_r * eccentricity_error(ecc, theta_m), 1e-13);
    c1 += eps * std::cos(theta_m);
    s1 += eps * std::sin(theta_m);
    c_pr += eps * std::cos(p_r * theta_m);
    s_pr += eps * std::sin(p_r * theta_m);
  }
  // Fourier over one mechanical turn: all of it at order 1 (p_r e), none at the
  // resolver's own order p_r, where the theta-domain estimators look.
  EXPECT_NEAR(2.0 / kGrid * std::hypot(c1, s1), p_r * 1e-3, 1e-12);
  EXPECT_NEAR(2.0 / kGrid * std::hypot(c_pr, s_pr), 0.0, 1e-12);
  // Sign: eps = -p_r e sin(theta_m + phase): at theta_m = pi/2 - phase it is -p_r e.
  EXPECT_NEAR(p_r * eccentricity_error(ecc, 0.5 * kPi - 0.7), -3e-3, 1e-15);
}

TEST(EffectsEccentricity, CompensationInvertsTheForwardModel) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(-20.0, 20.0);
  std::uniform_real_distribution<double> amp(-0.5, 0.5);
  for (int n = 0; n < 2000; ++n) {
    const EccentricityParams ecc{{"e", amp(rng)}, {"phase", angle(rng)}};
    const double theta_m = angle(rng);
    const double seen = eccentric_angle(ecc, theta_m);
    // The fixed-point iteration converges to rounding (|theta| <= 20: a few ulps of 20).
    ASSERT_NEAR(compensate_eccentricity(ecc, seen), theta_m, 1e-13) << ecc["e"];
    // The first-order inverse is wrong by |e (sin(seen + phase) - sin(theta_m + phase))| <= e^2.
    const double first_order = seen - ecc["e"] * std::sin(seen + ecc["phase"]);
    ASSERT_LE(std::abs(first_order - theta_m), ecc["e"] * ecc["e"] + 1e-13);
  }
}

TEST(EffectsMountingOffset, ShiftsTheResolverAndRotatesTheCurrents) {
  const MountingOffsetParams mounting{{"theta_0", 0.1}};  // [rad, motor electrical]
  const int p_r = 2;
  const int p = 4;
  ForwardChain chain = forward_chain({{"mounting_offset", "theta_0", mounting["theta_0"]}}, p_r, p);
  const double i_q = 10.0;
  for (int i = 0; i < 72; ++i) {
    const double theta_m = kTwoPi * (i + 0.3) / 72.0;
    // Resolver: shifted by (p_r / p) theta_0 = 0.05 rad resolver electrical.
    const double eps = p_r * theta_m - chain.resolver_angle(theta_m, 1.0, true);
    EXPECT_NEAR(eps, -0.05, 1e-14);
    EXPECT_NEAR(eps, mounting_offset_error(mounting, p_r, p), 1e-14);
    // Currents: ideal control in the drive frame theta_e + theta_0.
    const double theta_e = p * theta_m;
    const PhaseCurrents cur = chain.machine_currents(0.0, i_q, theta_e);
    const double i_alpha = cur.a;
    const double i_beta = (cur.b - cur.c) / std::numbers::sqrt3;
    const auto park = [&](double angle) {
      return DqCurrents{i_alpha * std::cos(angle) + i_beta * std::sin(angle),
                        -i_alpha * std::sin(angle) + i_beta * std::cos(angle)};
    };
    // With the reference (true) angle: a steady i_d = -i_q sin theta_0 (~ -1 A).
    const DqCurrents ref = park(theta_e);
    EXPECT_NEAR(ref.d, -i_q * std::sin(0.1), 1e-12);
    EXPECT_NEAR(ref.q, i_q * std::cos(0.1), 1e-12);
    // With the drive's own angle (p / p_r) theta_resolver: the command, no i_d at all.
    const DqCurrents drive = park(static_cast<double>(p) / p_r * chain.resolver_angle(theta_m, 1.0, true));
    EXPECT_NEAR(drive.d, 0.0, 1e-12);
    EXPECT_NEAR(drive.q, i_q, 1e-12);
    EXPECT_NEAR(estimate_mounting_offset(ref.d, ref.q, 0.0, i_q), 0.1, 1e-12);
    EXPECT_NEAR(compensate_mounting_offset(mounting, theta_e + 0.1), theta_e, 1e-12);
  }
  const DqCurrents rotated = mounting_offset_rotor_currents(mounting, 3.0, 4.0);
  EXPECT_NEAR(std::hypot(rotated.d, rotated.q), 5.0, 1e-14);  // a rotation keeps the magnitude
  EXPECT_NEAR(estimate_mounting_offset(rotated.d, rotated.q, 3.0, 4.0), 0.1, 1e-14);
}

}  // namespace
}  // namespace resolver
