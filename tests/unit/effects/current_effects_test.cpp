// The current-domain effects added in catalog v2: current sensor offsets, gain
// mismatch and inverter dead time. Each forward model (on phase currents: the
// registry's forward chain, forward_chain.h, machine then measured currents),
// transformed with an independent Clarke/Park (docs/ARCHITECTURE.md §3), is Fourier-analysed
// over one electrical turn and compared with the closed-form ripple the effect's
// header predicts. The models are linear in the currents, so the only error is
// floating-point rounding: sums of N = 720 terms of <= 20 A give < 1e-11 A, and
// the tolerance kRound = 1e-10 A says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

#include "daemon/core/angles.h"
#include "daemon/core/effects/current_gain_mismatch.h"
#include "daemon/core/effects/current_offsets.h"
#include "daemon/core/effects/dead_time.h"
#include "daemon/core/effects/effect.h"
#include "tests/unit/effects/chain_test_support.h"

namespace resolver {
namespace {

using test::forward_chain;

constexpr int kN = 720;          // theta_e grid over one electrical turn
constexpr int kMaxOrder = 8;     // orders 0..8 analysed
constexpr double kRound = 1e-10;  // [A] see the file comment

/// What the current sensors report for the command (i_d, i_q) [A] at true theta_e [rad].
PhaseCurrents measured_currents(const ForwardChain& chain, double i_d, double i_q, double theta_e) {
  return chain.measured_currents(chain.machine_currents(i_d, i_q, theta_e), theta_e);
}

DqCurrents to_dq(const PhaseCurrents& i, double theta_e) {
  const double i_alpha = i.a;
  const double i_beta = (i.b - i.c) / std::numbers::sqrt3;
  return {i_alpha * std::cos(theta_e) + i_beta * std::sin(theta_e),
          -i_alpha * std::sin(theta_e) + i_beta * std::cos(theta_e)};
}

/// Fourier coefficients of i_d and i_q over theta_e [A]: [0] is the mean, [n] the
/// coefficient of order n scaled so that |c_n| is that harmonic's peak amplitude.
struct Spectrum {
  std::array<std::complex<double>, kMaxOrder + 1> d{};
  std::array<std::complex<double>, kMaxOrder + 1> q{};
};

template <typename Currents>
Spectrum dq_spectrum(Currents&& currents_at, double offset = 0.13) {
  Spectrum s;
  for (int k = 0; k < kN; ++k) {
    const double theta_e = kTwoPi * (k + offset) / kN;
    const DqCurrents dq = to_dq(currents_at(theta_e), theta_e);
    for (int n = 0; n <= kMaxOrder; ++n) {
      const std::complex<double> w = std::polar(n == 0 ? 1.0 / kN : 2.0 / kN, -n * theta_e);
      s.d[static_cast<std::size_t>(n)] += dq.d * w;
      s.q[static_cast<std::size_t>(n)] += dq.q * w;
    }
  }
  return s;
}

/// Checks that only orders 0 and `order` carry anything, with the given amplitudes [A].
void expect_only(const Spectrum& s, int order, DqCurrents mean, DqCurrents amplitude) {
  for (int n = 0; n <= kMaxOrder; ++n) {
    const auto i = static_cast<std::size_t>(n);
    if (n == 0) {
      EXPECT_NEAR(s.d[i].real(), mean.d, kRound);
      EXPECT_NEAR(s.q[i].real(), mean.q, kRound);
    } else if (n == order) {
      EXPECT_NEAR(std::abs(s.d[i]), amplitude.d, kRound) << "order " << n;
      EXPECT_NEAR(std::abs(s.q[i]), amplitude.q, kRound) << "order " << n;
    } else {
      EXPECT_NEAR(std::abs(s.d[i]), 0.0, kRound) << "order " << n;
      EXPECT_NEAR(std::abs(s.q[i]), 0.0, kRound) << "order " << n;
    }
  }
}

TEST(EffectsCurrentOffsets, RippleAtOneTimesThetaE) {
  for (const auto& [off_a, off_b] : {std::pair{0.05, -0.03}, std::pair{0.0, 0.1}, std::pair{-0.2, 0.0}}) {
    const CurrentOffsetsParams offsets{{"off_a", off_a}, {"off_b", off_b}};
    const ForwardChain chain = forward_chain({{"current_offsets", "off_a", off_a}, {"current_offsets", "off_b", off_b}});
    const double i_d = -2.0;
    const double i_q = 10.0;
    const auto measured = [&](double theta_e) { return measured_currents(chain, i_d, i_q, theta_e); };
    // Clarke turns (off_a, off_b, 0) into the constant vector (off_a, off_b/sqrt3); Park spins it at -theta_e.
    const double amp = std::hypot(off_a, off_b / std::numbers::sqrt3);
    EXPECT_NEAR(current_offsets_ripple_1x(offsets), amp, 1e-15);
    expect_only(dq_spectrum(measured), 1, {i_d, i_q}, {amp, amp});
    for (int k = 0; k < 36; ++k) {
      const double theta_e = kTwoPi * k / 36.0;
      const DqCurrents err = current_offsets_dq_error(offsets, theta_e);
      const DqCurrents dq = to_dq(measured(theta_e), theta_e);
      EXPECT_NEAR(dq.d - i_d, err.d, kRound);
      EXPECT_NEAR(dq.q - i_q, err.q, kRound);
      const PhaseCurrents back = compensate_current_offsets(offsets, measured(theta_e));
      const PhaseCurrents ideal = ideal_phase_currents(i_d, i_q, theta_e);
      EXPECT_NEAR(back.a, ideal.a, kRound);
      EXPECT_NEAR(back.b, ideal.b, kRound);
      EXPECT_NEAR(back.c, ideal.c, kRound);
      // The phase sum exposes the offsets directly.
      const PhaseCurrents m = measured(theta_e);
      EXPECT_NEAR(m.a + m.b + m.c, off_a + off_b, kRound);
    }
  }
}

TEST(EffectsCurrentGainMismatch, RippleAtTwoTimesThetaE) {
  struct Case {
    double gain_a, gain_b, i_d, i_q;
  };
  for (const Case& c : {Case{0.01, 0.0, 0.0, 10.0}, Case{0.0, -0.02, 0.0, 10.0}, Case{0.01, 0.01, -3.0, 8.0},
                        Case{0.02, -0.01, 5.0, 0.0}}) {
    const CurrentGainMismatchParams gains{{"gain_a", c.gain_a}, {"gain_b", c.gain_b}};
    const ForwardChain chain =
        forward_chain({{"current_gain_mismatch", "gain_a", c.gain_a}, {"current_gain_mismatch", "gain_b", c.gain_b}});
    const auto measured = [&](double theta_e) { return measured_currents(chain, c.i_d, c.i_q, theta_e); };
    // Derivation (current_gain_mismatch.h): I = i_d + j i_q, i_a = Re(I e^{j th}),
    // i_b = Re(I e^{j(th - 2pi/3)}); the dq error (g_a i_a + j g_b i_b / sqrt3) e^{-j th} is
    //   I (g_a + g_b/2 - j g_b/(2 sqrt3))/2 + I* (g_a - g_b/2 - j g_b/(2 sqrt3))/2 e^{-2j th}.
    const std::complex<double> current(c.i_d, c.i_q);
    const double k3 = c.gain_b / (2.0 * std::numbers::sqrt3);
    const std::complex<double> dc = current * std::complex<double>(c.gain_a + 0.5 * c.gain_b, -k3) * 0.5;
    const double amp = 0.5 * std::abs(current) * std::abs(std::complex<double>(c.gain_a - 0.5 * c.gain_b, -k3));
    EXPECT_NEAR(current_gain_mismatch_ripple_2x(gains, c.i_d, c.i_q), amp, 1e-15);
    const Spectrum s = dq_spectrum(measured);
    expect_only(s, 2, {c.i_d + dc.real(), c.i_q + dc.imag()}, {amp, amp});
    EXPECT_GT(amp, 0.01) << "a visible ripple: the check above is not vacuous";
    for (int k = 0; k < 36; ++k) {
      const double theta_e = kTwoPi * k / 36.0;
      const DqCurrents err = current_gain_mismatch_dq_error(gains, c.i_d, c.i_q, theta_e);
      const DqCurrents dq = to_dq(measured(theta_e), theta_e);
      EXPECT_NEAR(dq.d - c.i_d, err.d, kRound);
      EXPECT_NEAR(dq.q - c.i_q, err.q, kRound);
      const PhaseCurrents back = compensate_current_gain_mismatch(gains, measured(theta_e));
      const PhaseCurrents ideal = ideal_phase_currents(c.i_d, c.i_q, theta_e);
      EXPECT_NEAR(back.a, ideal.a, kRound);
      EXPECT_NEAR(back.b, ideal.b, kRound);
    }
  }
}

/// The fit's prediction of the dq error (Effect::contribution at `gains`, operating point
/// `measured_mean` as prepare.cpp gives it) and its columns, at theta_e [rad].
SignalValues fit_contribution(const std::array<double, 2>& gains, DqCurrents measured_mean, double theta_e) {
  SignatureRow row;
  row.i_d0 = measured_mean.d;
  row.i_q0 = measured_mean.q;
  row.theta_e = theta_e;
  SignalValues out;
  current_gain_mismatch_effect().contribution(row, AngleBasis{}, gains, out);
  return out;
}

TEST(EffectsCurrentGainMismatch, TheFitsPredictionIsExactFromTheMeasuredOperatingPoint) {
  // The fit knows the measured mean current, I + DC(I), not the machine's I: at gains of
  // 13 % and -8 % (a real sensor's range) its prediction must still be the measured error
  // exactly, and its columns that prediction's derivatives (Gauss-Newton converges to the
  // exact fit only then; current_gain_mismatch.h).
  const std::array<double, 2> gains{0.13, -0.08};
  const double i_d = -3.0, i_q = 10.0;  // [A]
  const ForwardChain chain =
      forward_chain({{"current_gain_mismatch", "gain_a", gains[0]}, {"current_gain_mismatch", "gain_b", gains[1]}});
  const auto measured_dq = [&](double theta_e) {
    return to_dq(measured_currents(chain, i_d, i_q, theta_e), theta_e);
  };
  // The mean over a turn: the error has only orders 0 and 2, so kN points give it exactly.
  DqCurrents mean;
  for (int k = 0; k < kN; ++k) {
    const DqCurrents m = measured_dq(kTwoPi * k / kN);
    mean.d += m.d / kN;
    mean.q += m.q / kN;
  }
  const DqCurrents solved = current_gain_mismatch_operating_point({{"gain_a", gains[0]}, {"gain_b", gains[1]}}, mean);
  EXPECT_NEAR(solved.d, i_d, kRound);
  EXPECT_NEAR(solved.q, i_q, kRound);
  double first_order_miss = 0.0;
  for (int k = 0; k < 36; ++k) {
    const double theta_e = kTwoPi * (k + 0.3) / 36.0;
    const DqCurrents m = measured_dq(theta_e);
    const SignalValues predicted = fit_contribution(gains, mean, theta_e);
    EXPECT_NEAR(m.d - predicted.d, i_d, kRound);
    EXPECT_NEAR(m.q - predicted.q, i_q, kRound);
    // Control: the error taken at the measured mean (the first-order column) misses.
    const DqCurrents at_mean = current_gain_mismatch_dq_error({{"gain_a", gains[0]}, {"gain_b", gains[1]}}, mean.d,
                                                              mean.q, theta_e);
    first_order_miss = std::max(first_order_miss, std::abs(m.d - i_d - at_mean.d) + std::abs(m.q - i_q - at_mean.q));
    // Columns against central differences of the prediction: h = 1e-6 leaves O(h^2) of
    // truncation and ~1e-15 * 10 A / h = 1e-8 of rounding, hence 1e-7 [A per unit gain].
    SignatureRow row;
    row.i_d0 = mean.d;
    row.i_q0 = mean.q;
    row.theta_e = theta_e;
    std::array<SignalValues, 2> storage{};
    SignatureColumns cols(storage);
    current_gain_mismatch_effect().signature(row, AngleBasis{}, gains, cols);
    for (std::size_t p = 0; p < 2; ++p) {
      constexpr double kH = 1e-6;
      std::array<double, 2> up = gains, down = gains;
      up[p] += kH;
      down[p] -= kH;
      const SignalValues hi = fit_contribution(up, mean, theta_e), lo = fit_contribution(down, mean, theta_e);
      EXPECT_NEAR(cols.col(p).d, (hi.d - lo.d) / (2.0 * kH), 1e-7) << "parameter " << p;
      EXPECT_NEAR(cols.col(p).q, (hi.q - lo.q) / (2.0 * kH), 1e-7) << "parameter " << p;
    }
  }
  // |DC| ~ 0.6 A at these gains, and the gains' error on it ~0.1 A.
  EXPECT_GT(first_order_miss, 0.01) << "the first-order column would pass too: the check is vacuous";
}

TEST(EffectsDeadTime, FifthAndSeventhGiveRippleAtSixTimesThetaE) {
  for (const auto& current : {std::pair{0.0, 10.0}, std::pair{-4.0, 6.0}, std::pair{5.0, 0.0}}) {
    const double i_d = current.first;  // [A] (locals, not a structured binding: lambdas capture them)
    const double i_q = current.second;
    const DeadTimeParams dead{{"t_d", 2e-6}};  // [s] -> k_dt = 0.02
    const ForwardChain chain = forward_chain({{"dead_time", "t_d", dead["t_d"]}});
    const double k = 2e-6 / 100e-6;
    EXPECT_DOUBLE_EQ(dead_time_k_dt(dead), k);
    const auto measured = [&](double theta_e) { return measured_currents(chain, i_d, i_q, theta_e); };
    // Header: delta i_d = 2 k i_q cos(6(theta_e + delta)), delta i_q = -2 k i_d cos(...).
    expect_only(dq_spectrum(measured), 6, {i_d, i_q}, {2.0 * k * std::abs(i_q), 2.0 * k * std::abs(i_d)});
    const DqCurrents predicted = dead_time_ripple_6x(dead, i_d, i_q);
    EXPECT_NEAR(predicted.d, 2.0 * k * std::abs(i_q), 1e-15);
    EXPECT_NEAR(predicted.q, 2.0 * k * std::abs(i_d), 1e-15);
    // Phase a itself: 5th and 7th harmonics of k |I| each, no 3rd (three-wire), sum zero.
    const double magnitude = std::hypot(i_d, i_q);
    std::array<std::complex<double>, 8> phase_a{};
    for (int j = 0; j < kN; ++j) {
      const double theta_e = kTwoPi * (j + 0.13) / kN;
      const PhaseCurrents cur = measured(theta_e);
      ASSERT_NEAR(cur.a + cur.b + cur.c, 0.0, kRound);
      for (int n = 0; n < 8; ++n) phase_a[static_cast<std::size_t>(n)] += cur.a * std::polar(2.0 / kN, -n * theta_e);
      const DqCurrents err = dead_time_dq_error(dead, i_d, i_q, theta_e);
      const DqCurrents dq = to_dq(cur, theta_e);
      ASSERT_NEAR(dq.d - i_d, err.d, kRound);
      ASSERT_NEAR(dq.q - i_q, err.q, kRound);
    }
    EXPECT_NEAR(std::abs(phase_a[1]), magnitude, kRound);
    EXPECT_NEAR(std::abs(phase_a[3]), 0.0, kRound);
    EXPECT_NEAR(std::abs(phase_a[5]), k * magnitude, kRound);
    EXPECT_NEAR(std::abs(phase_a[7]), k * magnitude, kRound);
  }
}

TEST(EffectsCurrentChain, IdealChainIsIdealControlAndEffectsCompose) {
  const ForwardChain ideal = forward_chain({});
  const ForwardChain chain = forward_chain({{"current_gain_mismatch", "gain_a", 0.01},
                                            {"current_gain_mismatch", "gain_b", -0.02},
                                            {"current_offsets", "off_a", 0.05},
                                            {"current_offsets", "off_b", -0.04}});
  for (int k = 0; k < 36; ++k) {
    const double theta_e = kTwoPi * k / 36.0;
    const PhaseCurrents want = ideal_phase_currents(1.0, 9.0, theta_e);
    const PhaseCurrents got = measured_currents(ideal, 1.0, 9.0, theta_e);
    EXPECT_EQ(got.a, want.a);
    EXPECT_EQ(got.b, want.b);
    EXPECT_EQ(got.c, want.c);
    // Sensor order: gain first, then offset (an offset is not scaled by the gain error).
    const PhaseCurrents m = chain.measured_currents(want, theta_e);
    EXPECT_NEAR(m.a, 1.01 * want.a + 0.05, 1e-14);
    EXPECT_NEAR(m.b, 0.98 * want.b - 0.04, 1e-14);
    EXPECT_EQ(m.c, want.c);
  }
}

}  // namespace
}  // namespace resolver
