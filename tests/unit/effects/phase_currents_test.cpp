#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "daemon/core/angles.h"
#include "daemon/core/effects/phase_currents.h"
#include "tests/unit/effects/chain_test_support.h"

namespace resolver {
namespace {

/// Forward Clarke + Park of docs/ARCHITECTURE.md §3, written out independently of the library.
struct Dq {
  double d;
  double q;
};
Dq to_dq(const PhaseCurrents& i, double theta_e) {
  const double i_alpha = i.a;
  const double i_beta = (i.b - i.c) / std::numbers::sqrt3;
  return {i_alpha * std::cos(theta_e) + i_beta * std::sin(theta_e),
          -i_alpha * std::sin(theta_e) + i_beta * std::cos(theta_e)};
}

TEST(EffectsPhaseCurrents, TransformBackExactlyWithTheTrueAngle) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-10.0, 10.0);
  std::uniform_real_distribution<double> amps(-50.0, 50.0);
  for (int n = 0; n < 1000; ++n) {
    const double i_d = amps(rng);
    const double i_q = amps(rng);
    const double theta_e = angle(rng);
    const PhaseCurrents i = ideal_phase_currents(i_d, i_q, theta_e);
    // Rounding only: a few ulps of 50 A.
    ASSERT_NEAR(i.a + i.b + i.c, 0.0, 1e-12);
    const Dq dq = to_dq(i, theta_e);
    ASSERT_NEAR(dq.d, i_d, 1e-12);
    ASSERT_NEAR(dq.q, i_q, 1e-12);
  }
}

TEST(EffectsPhaseCurrents, HwangSetupPureQCurrent) {
  // Hwang eqs. 11-12 (with theta_e = w_e t): i_alpha = -I_m sin(theta_e), i_beta = I_m cos(theta_e).
  const double i_m = 10.0;
  for (int k = 0; k < 36; ++k) {
    const double theta_e = kTwoPi * k / 36.0;
    const PhaseCurrents i = ideal_phase_currents(0.0, i_m, theta_e);
    EXPECT_NEAR(i.a, -i_m * std::sin(theta_e), 1e-12);
    EXPECT_NEAR((i.b - i.c) / std::numbers::sqrt3, i_m * std::cos(theta_e), 1e-12);
  }
}

TEST(EffectsPhaseCurrents, ImbalanceShowsHwangEq15InD) {
  // p_r = p, so theta_e = theta. The drive transforms with the R/D angle
  // phi = theta - eps; the exact result is i_d = -I_m sin(eps), i_q = I_m cos(eps).
  // Hwang eq. 15: i_d = -I_m (alpha/2) sin 2theta_e. (Hwang eq. 16's O(alpha) q ripple
  // comes from rotating with the raw sin/cos signals, eq. 14; with an R/D angle the
  // q ripple is O(alpha^2), checked below.)
  const double i_m = 10.0;
  const double alpha = 0.003;  // Hwang's experiment: 0.3 %
  const ForwardChain chain = test::forward_chain({{"amplitude_imbalance", "alpha", alpha}});
  // |eps - (alpha/2) sin 2theta| <= b (series bound, see signatures_test) and
  // |sin(eps) - eps| <= |eps|^3/6.
  const double q = alpha / (2.0 + alpha);
  const double b = std::abs(0.5 * alpha - q) + (-std::log1p(-q) - q);
  const double e_max = 0.5 * alpha + b;
  const double tol = i_m * (b + e_max * e_max * e_max / 6.0);
  double max_d = 0.0;
  for (int k = 0; k < 720; ++k) {
    const double theta_e = kTwoPi * (k + 0.25) / 720.0;
    const double phi = static_rd_angle(chain.envelopes(theta_e));
    const Dq dq = to_dq(ideal_phase_currents(0.0, i_m, theta_e), phi);
    ASSERT_NEAR(dq.d, -i_m * 0.5 * alpha * std::sin(2.0 * theta_e), tol) << k;
    ASSERT_NEAR(dq.q, i_m, i_m * 0.5 * e_max * e_max);
    max_d = std::max(max_d, std::abs(dq.d));
  }
  EXPECT_NEAR(max_d, i_m * alpha / 2.0, tol);  // the ripple is really there: 15 mA
}

}  // namespace
}  // namespace resolver
