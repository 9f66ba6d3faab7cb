// The registry's motion effects through the simulator, against the reference
// encoder: delay (eps = omega d), backlash (eps = p_r (h/2) sign(omega), a
// standstill of h of travel after a reversal) and mechanical harmonics (orders
// n / p_r of theta). Each on a quiet chain (no noise, ideal converter), so the
// only other errors in a sample are known roundings:
//   - R/D angle: the 16-bit field, |error| <= LSB / 2 = pi / 2^16 [rad];
//   - reference: 2^32 counts per mechanical turn, |error| <= pi / 2^32 mechanical
//     rad, p_r times that in resolver electrical rad (< 3e-9 rad);
//   - sin/cos: rounding each channel to a whole count moves atan2 by at most
//     0.5 sqrt2 / A = 0.71 / A [rad] (A = amplitude_counts).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/quantization.h"
#include "tests/unit/sim/sim_test_support.h"
#include "tools/sim/bench_simulator.h"

namespace resolver {
namespace {

using test::quiet;
using test::rd_error_vs_reference;
using test::reference_angle_m;
using test::run;

/// [rad] rounding of the R/D field plus the reference's (see the file comment).
double rd_tolerance(int p_r) { return 0.5 * quantization_lsb(16) + p_r * kPi / 4294967296.0 + 1e-12; }
/// [rad] the same for the angle atan2 of the rounded sin/cos counts.
double sincos_tolerance(const SimConfig& c) { return 0.71 / c.amplitude_counts + c.p_r * kPi / 4294967296.0; }

/// [rad] resolver electrical speed of a hold at `rpm`.
double resolver_speed(const SimConfig& c, double rpm) { return c.p_r * rpm * kTwoPi / 60.0; }

TEST(SimDelay, ErrorAgainstTheReferenceIsOmegaDAndFlipsBackwards) {
  const double d = 2e-4;  // [s] e.g. a fieldbus latency
  for (const double rpm : {200.0, 1000.0, -1000.0}) {
    SimConfig c = quiet(rpm, 0.1);
    c.chain.set("delay", "d", d);
    // delay.h: at constant speed theta(t) - theta(t - d) = omega d exactly, and
    // the resolver's own (ideal) signals add nothing else.
    const double want = resolver_speed(c, rpm) * d;
    for (const SimSample& s : run(c)) {
      ASSERT_NEAR(rd_error_vs_reference(s, c.p_r), want, rd_tolerance(c.p_r)) << rpm << " r/min, sample " << s.index;
      // The envelopes turn with the late angle too: the sin/cos angle shows the same error.
      const double eps_sc = wrap_pi(c.p_r * reference_angle_m(s) - std::atan2(s.sin_counts, s.cos_counts));
      ASSERT_NEAR(eps_sc, want, sincos_tolerance(c)) << rpm << " r/min, sample " << s.index;
    }
    // 200 r/min: 0.0126 rad; 1000 r/min: 0.0628 rad; backwards: -0.0628 rad. Far above the roundings.
    EXPECT_GT(std::abs(want), 100.0 * rd_tolerance(c.p_r));
  }
}

/// Index of the largest value.
std::size_t argmax(const std::vector<double>& v) {
  return static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());
}

TEST(SimBacklash, OffsetFlipsWithDirectionAndTheTakeUpLastsThePlay) {
  // Forward 0.3 s, a 0.2 s ramp through standstill (at t = 0.4 s, sample 800), backward 0.3 s.
  for (const double h : {0.02, 0.04}) {  // [rad, mechanical] two plays: the take-up scales with h
    SimConfig c = quiet(200.0, 0.3);
    c.profile = {{0.3, 200.0, 200.0}, {0.2, 200.0, -200.0}, {0.3, -200.0, -200.0}};
    c.chain.set("backlash", "h", h);
    const std::vector<SimSample> samples = run(c);
    std::vector<double> theta_m;  // [rad] continuous reference angle
    theta_m.reserve(samples.size());
    AngleUnwrapper unwrap;
    for (const SimSample& s : samples) theta_m.push_back(unwrap.update(reference_angle_m(s)));
    const std::size_t turn = argmax(theta_m);
    ASSERT_EQ(turn, 800U) << "the reversal is at t = 0.4 s";
    const double tol = rd_tolerance(c.p_r);
    const double level = 0.5 * c.p_r * h;  // [rad] backlash.h: eps = p_r (h/2) sign(omega)
    // Forward: the resolver lags by h/2, eps = +p_r h/2 (from the first sample: the
    // simulator starts with the gap taken up in the direction of motion).
    for (std::size_t k = 0; k <= turn; ++k) {
      ASSERT_NEAR(rd_error_vs_reference(samples[k], c.p_r), level, tol) << "h " << h << ", sample " << k;
    }
    // After the reversal: the resolver stands still (the same R/D count) while the
    // reference travels back through the play, eps = p_r (h/2 - travel); then it
    // follows h/2 behind in the new direction, eps = -p_r h/2.
    std::size_t last_standing = turn;
    double step_max = 0.0;  // [rad] largest reference step per sample while taking up
    for (std::size_t k = turn + 1; k < samples.size(); ++k) {
      const double travel = theta_m[turn] - theta_m[k];
      const double eps = rd_error_vs_reference(samples[k], c.p_r);
      if (travel <= h) {
        ASSERT_EQ(samples[k].rd_counts, samples[turn].rd_counts) << "standing still, h " << h << ", sample " << k;
        ASSERT_NEAR(eps, c.p_r * (0.5 * h - travel), tol) << "take-up, h " << h << ", sample " << k;
        step_max = std::max(step_max, theta_m[k - 1] - theta_m[k]);
      } else {
        ASSERT_NEAR(eps, -level, tol) << "backwards, h " << h << ", sample " << k;
      }
      if (samples[k].rd_counts == samples[turn].rd_counts) last_standing = k;
    }
    // Measured from the log alone: the reference travel while the R/D angle stood
    // still is h, within one sample's travel (when the take-up ends between two
    // samples) plus one R/D count (p_r LSB_mech: a first move smaller than a count).
    const double standing_travel = theta_m[turn] - theta_m[last_standing];
    EXPECT_NEAR(standing_travel, h, step_max + quantization_lsb(16) / c.p_r) << "h " << h;
    EXPECT_LT(step_max, 0.1 * h) << "the travel resolution is fine enough to mean something";
  }
}

TEST(SimMechanicalHarmonics, OrderTwoOfTheMechanicalTurnAgainstTheReference) {
  const double a2 = 1e-3;   // [rad, mechanical] e.g. an angular coupling misalignment
  const double b2 = -5e-4;  // [rad, mechanical]
  SimConfig c = quiet(200.0, 0.6);  // 200 r/min at 2 kHz: 600 samples per mechanical turn, two turns
  c.chain.set("mechanical_harmonics", "a2", a2);
  c.chain.set("mechanical_harmonics", "b2", b2);
  const std::vector<SimSample> samples = run(c);
  ASSERT_EQ(samples.size(), 1200U);
  // Fourier over whole mechanical turns in theta_m: orders 1..6 (order p_r = 3 is theta itself).
  constexpr int kOrders = 6;
  std::array<std::complex<double>, kOrders + 1> coef{};
  const double n = static_cast<double>(samples.size());
  for (const SimSample& s : samples) {
    const double theta_m = reference_angle_m(s);
    const double eps = rd_error_vs_reference(s, c.p_r);
    // mechanical_harmonics.h: eps = -p_r (a_2 sin 2theta_m + b_2 cos 2theta_m), exact in the true angle.
    ASSERT_NEAR(eps, -c.p_r * (a2 * std::sin(2.0 * theta_m) + b2 * std::cos(2.0 * theta_m)), rd_tolerance(c.p_r))
        << s.index;
    const double eps_sc = wrap_pi(c.p_r * theta_m - std::atan2(s.sin_counts, s.cos_counts));
    ASSERT_NEAR(eps_sc, eps, sincos_tolerance(c) + rd_tolerance(c.p_r)) << "the envelopes turn with the seen angle";
    for (int k = 1; k <= kOrders; ++k) coef[static_cast<std::size_t>(k)] += eps * std::polar(2.0 / n, -k * theta_m);
  }
  // coef = (cos part) - j (sin part). Rounding (<= LSB/2 per sample) moves a
  // coefficient 2/N sum(...) by at most one LSB.
  const double tol = quantization_lsb(16);
  EXPECT_NEAR(-coef[2].imag(), -c.p_r * a2, tol);
  EXPECT_NEAR(coef[2].real(), -c.p_r * b2, tol);
  for (int k : {1, 3, 4, 5, 6}) {
    // Nothing at the resolver's own orders (3 = theta, 6 = 2 theta): a fit over theta alone cannot see it.
    EXPECT_NEAR(std::abs(coef[static_cast<std::size_t>(k)]), 0.0, tol) << "mechanical order " << k;
  }
  EXPECT_GT(c.p_r * std::hypot(a2, b2), 30.0 * tol);
}

}  // namespace
}  // namespace resolver
