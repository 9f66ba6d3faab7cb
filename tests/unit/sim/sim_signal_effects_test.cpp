// The registry's signal effects through the simulator: channel delay (a
// quadrature of beta = -omega tau that the R/D angle shows, unlike the DSP's
// sampling skew), opposite-sequence harmonics (k3_opp: a 4theta error, sin/cos
// at 3theta with opposite signs) and outliers (their rate and size in the log).
// Quiet chain (no noise, ideal converter); roundings as in sim_motion_effects_test:
// R/D field LSB/2, sin/cos 0.5 count per channel.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdlib>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/quadrature.h"
#include "daemon/core/effects/quantization.h"
#include "tests/unit/effects/chain_test_support.h"
#include "tests/unit/sim/sim_test_support.h"
#include "tools/sim/bench_simulator.h"

namespace resolver {
namespace {

using test::quiet;
using test::run;

using test::quadrature_remainder_bound;

const double kHalfLsb = 0.5 * quantization_lsb(16);  // [rad] half a count of the 16-bit R/D field

TEST(SimChannelDelay, RdAngleShowsQuadratureMinusOmegaTauUnlikeSamplingSkew) {
  const double tau = 2e-5;  // [s] the cos path's extra group delay
  const double rpm = 1000.0;
  for (const bool analog : {true, false}) {  // channel_delay (analog path) vs sampling_skew (the DSP's)
    SimConfig c = quiet(rpm, 0.2);           // 10 electrical turns of 40 samples
    c.chain.set(analog ? "channel_delay" : "sampling_skew", "tau", tau);
    const double omega = c.p_r * rpm * kTwoPi / 60.0;  // [rad/s] resolver electrical
    // At constant speed theta(t -/+ tau) = theta -/+ omega tau exactly: the cos channel
    // is cos(theta + beta) with beta = -omega tau (delayed) or +omega tau (sampled late).
    const double beta = analog ? -omega * tau : omega * tau;
    const ForwardChain quad = test::forward_chain({{"quadrature", "beta", beta}});
    const double sc_tol = 0.71 / (c.amplitude_counts * (1.0 - std::abs(beta)));  // count rounding near radius 1 - |beta|
    double mean_rd = 0.0;
    const std::vector<SimSample> samples = run(c);
    for (const SimSample& s : samples) {
      const double eps_rd = wrap_pi(s.theta - s.rd_angle);
      const double eps_sc = wrap_pi(s.theta - std::atan2(s.sin_counts, s.cos_counts));
      // The DSP's samples: the same quadrature for both effects, with opposite beta.
      ASSERT_NEAR(eps_sc, test::exact_error(quad, s.theta), sc_tol) << s.index;
      if (analog) {
        // The converter sees the delayed cos too: the exact quadrature error, and
        // to first order (omega tau / 2)(1 - cos 2theta) (channel_delay.h).
        ASSERT_NEAR(eps_rd, test::exact_error(quad, s.theta), kHalfLsb + 1e-12) << s.index;
        ASSERT_NEAR(eps_rd, quadrature_error({{"beta", beta}}, s.theta), kHalfLsb + quadrature_remainder_bound(beta))
            << s.index;
      } else {
        // The converter has its own analog front end: no error at all.
        ASSERT_NEAR(eps_rd, 0.0, kHalfLsb + 1e-12) << s.index;
      }
      mean_rd += eps_rd;
    }
    mean_rd /= static_cast<double>(samples.size());
    // Over whole turns the 2theta part averages out: the R/D angle's mean error is
    // -beta/2 = +omega tau / 2 (3.1e-3 rad) for the delay, 0 for the skew.
    EXPECT_NEAR(mean_rd, analog ? 0.5 * omega * tau : 0.0, kHalfLsb + quadrature_remainder_bound(beta)) << analog;
  }
}

/// Fourier coefficients over whole turns of theta: |c[n]| is the amplitude of order n,
/// c[n] = (cos part) - j (sin part).
template <std::size_t N>
void add_fourier(std::array<std::complex<double>, N>& c, double value, double theta, double n_samples) {
  for (std::size_t k = 1; k < N; ++k) c[k] += value * std::polar(2.0 / n_samples, -static_cast<double>(k) * theta);
}

TEST(SimHarmonics, OppositeSequenceK3GivesFourThetaAndOppositeSignsAtThreeTheta) {
  const double k = 5e-3;  // [fraction of fundamental]
  // Control: the same-sequence K_3 (Hanselman eq. 8-9) puts its error at 2theta, same sign on both channels.
  for (const bool opposite : {true, false}) {
    SimConfig c = quiet(200.0, 0.5);  // 10 electrical turns/s at 2 kHz: 200 samples per turn, 5 turns
    c.chain.set("harmonics", opposite ? "k3_opp" : "k3", k);
    const std::vector<SimSample> samples = run(c);
    ASSERT_EQ(samples.size(), 1000U);
    const double n = static_cast<double>(samples.size());
    const double a = c.amplitude_counts;
    std::array<std::complex<double>, 9> eps{};
    std::array<std::complex<double>, 4> sin_res{};
    std::array<std::complex<double>, 4> cos_res{};
    for (const SimSample& s : samples) {
      add_fourier(eps, wrap_pi(s.theta - s.rd_angle), s.theta, n);
      add_fourier(sin_res, s.sin_counts - a * std::sin(s.theta), s.theta, n);
      add_fourier(cos_res, s.cos_counts - a * std::cos(s.theta), s.theta, n);
    }
    // harmonics.h: eps ~ -K_3_opp sin 4theta (opposite) or -K_3 sin 2theta (same), plus
    // second-order terms <= d^2 / (2 (1-d)^2), d = sqrt2 K (the atan2 bound, signatures_test),
    // plus rounding: a coefficient 2/N sum(...) of values <= LSB/2 moves by <= one LSB.
    const double tol = 2.0 * kHalfLsb + test::atan2_second_order_bound(std::sqrt(2.0) * k);
    const std::size_t order = opposite ? 4 : 2;
    for (std::size_t m = 1; m < eps.size(); ++m) {
      if (m == order) {
        EXPECT_NEAR(-eps[m].imag(), -k, tol) << "sin part at order " << m;
        EXPECT_NEAR(eps[m].real(), 0.0, tol) << "cos part at order " << m;
      } else {
        EXPECT_NEAR(std::abs(eps[m]), 0.0, tol) << (opposite ? "k3_opp" : "k3") << ", order " << m;
      }
    }
    // The envelopes: s += (K_3 + K_3_opp) sin 3theta, c += (K_3 - K_3_opp) cos 3theta. Rounding each
    // count (<= 0.5) moves a coefficient by <= 1 count; A K = 130 counts.
    const double count_tol = 1.0;
    EXPECT_NEAR(-sin_res[3].imag(), a * k, count_tol);
    EXPECT_NEAR(cos_res[3].real(), opposite ? -a * k : a * k, count_tol);
    EXPECT_NEAR(std::abs(sin_res[1]) + std::abs(cos_res[1]) + std::abs(sin_res[2]) + std::abs(cos_res[2]), 0.0,
                4.0 * count_tol);
    EXPECT_GT(k, 20.0 * tol);
  }
}

TEST(SimOutliers, RateAndSizeShowInTheLog) {
  const double rate = 50.0;    // [1/s]
  const double size = 3000.0;  // [counts]
  SimConfig clean = quiet(200.0, 20.0);
  SimConfig spiky = clean;
  spiky.chain.set("outliers", "rate", rate);
  spiky.chain.set("outliers", "size", size);
  const std::vector<SimSample> a = run(clean);
  const std::vector<SimSample> b = run(spiky);
  ASSERT_EQ(a.size(), b.size());
  // Only the sin channel (test::changed_signals: not the cos, R/D angle, currents or reference).
  EXPECT_EQ(test::changed_signals(a, b), test::kSinCos);
  int spikes = 0;
  int positive = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].cos_counts, b[i].cos_counts) << i;
    const int diff = b[i].sin_counts - a[i].sin_counts;
    if (diff == 0) continue;
    // Every spike has the configured size exactly (an integer, so the rounding to counts keeps it).
    ASSERT_EQ(std::abs(diff), static_cast<int>(size)) << i;
    ++spikes;
    if (diff > 0) ++positive;
  }
  // Bernoulli per sample with p = rate / fs = 0.025 over N = 40000 samples: the count
  // is binomial, mean N p = 1000, sd sqrt(N p (1 - p)) = 31; 5 sd either side.
  const double n = static_cast<double>(a.size());
  const double p = rate / clean.sample_rate_hz;
  const double sd = std::sqrt(n * p * (1.0 - p));
  EXPECT_NEAR(spikes, n * p, 5.0 * sd);
  EXPECT_NEAR(spikes / 20.0, rate, 5.0 * sd / 20.0) << "[1/s] the rate read back from the log";
  // Random sign: positive ones are binomial(spikes, 1/2), sd sqrt(spikes)/2; 5 sd.
  EXPECT_NEAR(positive, 0.5 * spikes, 2.5 * std::sqrt(static_cast<double>(spikes)));
}

}  // namespace
}  // namespace resolver
