// Clarke/Park conventions (docs/ARCHITECTURE.md §3), ripple measurement, and Hwang eqs. 15-16.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "daemon/core/angles.h"
#include "daemon/core/estimation/dq_transform.h"
#include "daemon/core/estimation/revolution_ripple.h"
#include "daemon/core/estimation/sample_processor.h"

namespace resolver {
namespace {

// Inverse transforms written independently here (not shared with the code under test).
void phase_currents(double i_d, double i_q, double theta_e, double& a, double& b, double& c) {
  const double alpha = i_d * std::cos(theta_e) - i_q * std::sin(theta_e);
  const double beta = i_d * std::sin(theta_e) + i_q * std::cos(theta_e);
  a = alpha;
  b = -0.5 * alpha + std::numbers::sqrt3 / 2.0 * beta;
  c = -0.5 * alpha - std::numbers::sqrt3 / 2.0 * beta;
}

TEST(DqTransform, RoundTripsAtManyAngles) {
  for (int k = 0; k < 360; ++k) {
    const double th = kTwoPi * k / 360.0;
    double a, b, c;
    phase_currents(1.5, -4.0, th, a, b, c);
    const ClarkeTransform ab(a, b, c);
    const ParkTransform dq(ab.alpha, ab.beta, th);
    EXPECT_NEAR(dq.d, 1.5, 1e-12);
    EXPECT_NEAR(dq.q, -4.0, 1e-12);
  }
}

TEST(DqTransform, HwangEq11And12) {
  // i_d = 0, i_q = I_m gives i_alpha = -I_m sin(theta_e), i_beta = I_m cos(theta_e).
  double a, b, c;
  phase_currents(0.0, 2.0, 0.7, a, b, c);
  const ClarkeTransform ab(a, b, c);
  EXPECT_NEAR(ab.alpha, -2.0 * std::sin(0.7), 1e-12);
  EXPECT_NEAR(ab.beta, 2.0 * std::cos(0.7), 1e-12);
}

TEST(RevolutionRipple, MeasuresEachOrder) {
  RevolutionRipple r;
  const int n = 400;  // samples per revolution
  bool done = false;
  for (int i = 0; i < 3 * n + 5; ++i) {
    const double th = 0.1 + kTwoPi * i / n;
    const double d = 0.5 + 0.02 * std::cos(2.0 * th + 0.3) + 0.005 * std::sin(6.0 * th);
    const double q = 3.0 + 0.01 * std::cos(th - 1.0);
    done = r.update(th, d, q) || done;
  }
  ASSERT_TRUE(done);
  // Exact for sinusoids sampled uniformly over whole revolutions, up to one
  // sample of misalignment of the window (the window starts at the first
  // sample past a boundary): error O(1/n) relative.
  const double tol = 2.0 / n;
  EXPECT_NEAR(r.last().d[1], 0.02, 0.02 * tol);
  EXPECT_NEAR(r.last().d[2], 0.005, 0.005 * tol + 1e-12);
  EXPECT_NEAR(r.last().d[0], 0.0, 0.02 * tol);
  EXPECT_NEAR(r.last().q[0], 0.01, 0.01 * tol);
  EXPECT_NEAR(r.last().q[1], 0.0, 0.01 * tol);
}

TEST(SampleProcessor, HwangEq15And16RippleAndCompensation) {
  // p_r = p: i_d with the R/D angle carries I_m alpha/2 at 2 theta_e (Hwang
  // eq. 15). With the error in the angle (not in the transform's gains, as in
  // Hwang's eq. 14), i_q = I_m cos(eps) has no first-order 2x ripple: its
  // ripple is I_m eps^2/2 at 0x and 4x, so its 2x amplitude must be tiny.
  // After convergence the compensated angle removes the i_d ripple.
  const double alpha = 0.003, i_m = 10.0, rate = 2000.0, omega = kTwoPi * 10.0;
  ProcessorConfig pc;
  pc.method = EstimatorMethod::kHwangIntegral;  // this test is about Hwang's estimator and its compensation
  pc.p_r = 3;
  pc.p = 3;
  SampleProcessor proc(pc);
  RippleSet early{};
  bool have_early = false;
  for (int i = 0; i < static_cast<int>(4.0 * rate); ++i) {
    const double t = i / rate;
    const double theta = 0.2 + omega * t;  // true resolver electrical = motor electrical here
    SampleInput in;
    in.t = t;
    in.has_rd = true;
    in.theta_rd = wrap_2pi(std::atan2(std::sin(theta), (1.0 + alpha) * std::cos(theta)));
    in.has_currents = true;
    phase_currents(0.0, i_m, theta, in.i_a, in.i_b, in.i_c);
    const SampleOutput out = proc.process(in);
    if (out.ripple_raw_updated && !have_early && proc.ripple().raw_valid) {
      early = proc.ripple();
      have_early = true;
    }
  }
  ASSERT_TRUE(have_early);
  ASSERT_TRUE(proc.estimator().converged());
  // Exact 2x amplitude of sin(eps) is I_m q with q = alpha/(2+alpha) ~ alpha/2.
  const double expected = i_m * alpha / (2.0 + alpha);
  EXPECT_NEAR(early.raw.d[1], expected, expected * 0.01);
  EXPECT_LT(early.raw.q[1], i_m * alpha * alpha);
  // Residual after compensation: the estimator's 2q vs the exact coefficient
  // differ at O(alpha^2); the compensated 2x ripple must fall by >= 40 dB.
  EXPECT_LT(proc.ripple().comp.d[1], expected / 100.0);

}

}  // namespace
}  // namespace resolver
