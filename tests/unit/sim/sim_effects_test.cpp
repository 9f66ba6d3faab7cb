// The simulator honours every catalog effect: each spec changes exactly the
// signals the effect physically reaches, the truth file names it, and the
// catalog v2 effects carry their signature in the samples.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/effect_catalog.h"
#include "daemon/core/effects/quantization.h"
#include "tools/sim/bench_simulator.h"
#include "tools/sim/sim_truth.h"

namespace resolver {
namespace {

// Which recorded signals a spec changes.
constexpr unsigned kSinCos = 1U;
constexpr unsigned kRd = 2U;
constexpr unsigned kCurrents = 4U;
constexpr unsigned kReference = 8U;

std::vector<SimSample> run(const SimConfig& c) {
  BenchSimulator sim(c);
  std::vector<SimSample> out;
  SimSample s{};
  while (sim.next(s)) out.push_back(s);
  return out;
}

unsigned changed_signals(const std::vector<SimSample>& a, const std::vector<SimSample>& b) {
  unsigned mask = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    if (a[i].sin_counts != b[i].sin_counts || a[i].cos_counts != b[i].cos_counts) mask |= kSinCos;
    if (a[i].rd_counts != b[i].rd_counts) mask |= kRd;
    if (a[i].i_a_ma != b[i].i_a_ma || a[i].i_b_ma != b[i].i_b_ma || a[i].i_c_ma != b[i].i_c_ma) mask |= kCurrents;
    if (a[i].ref_counts != b[i].ref_counts) mask |= kReference;
  }
  return mask;
}

TEST(SimEffects, EverySpecChangesExactlyTheSignalsItReaches) {
  // One visible spec per catalog effect, and the signals it must (and must only) change.
  const std::map<std::string, std::pair<std::string, unsigned>> table{
      {"amplitude_imbalance", {"amplitude_imbalance:alpha=0.01", kSinCos | kRd}},
      {"quadrature", {"quadrature:beta=0.01", kSinCos | kRd}},
      {"offsets", {"offsets:o_s=0.01", kSinCos | kRd}},
      {"harmonics", {"harmonics:k3=0.005", kSinCos | kRd}},
      {"sampling_skew", {"sampling_skew:tau=2e-5", kSinCos}},  // the DSP's sampling, not the converter
      {"tracking_loop", {"tracking_loop:omega_n=1000", kRd}},
      {"quantization", {"quantization:rd_bits=12", kRd}},
      {"eccentricity", {"eccentricity:e=1e-3,phase=0.4", kSinCos | kRd}},
      {"mounting_offset", {"mounting_offset:theta_0=0.1", kSinCos | kRd | kCurrents}},
      {"current_offsets", {"current_offsets:off_a=0.1,off_b=-0.05", kCurrents}},
      {"current_gain_mismatch", {"current_gain_mismatch:gain_a=0.02", kCurrents}},
      {"dead_time", {"dead_time:t_d=2e-6", kCurrents}},
      {"noise", {"noise:sigma_sc=5", kSinCos}},
  };
  SimConfig base;  // default chain: noise and tracking loop on, same seed for every run
  // A hold and a ramp: at constant speed a type-II loop tracks an ideal resolver
  // without error, under acceleration it lags by a / omega_n^2.
  base.profile = {{0.05, 1000.0, 1000.0}, {0.05, 1000.0, 2000.0}};
  const std::vector<SimSample> baseline = run(base);
  for (const EffectInfo& e : effect_catalog()) {
    const auto it = table.find(std::string(e.name));
    ASSERT_NE(it, table.end()) << "add a spec for the new catalog effect " << e.name;
    SimConfig c = base;
    const auto err = apply_effect_spec(c.chain, it->second.first);
    ASSERT_FALSE(err.has_value()) << *err;
    EXPECT_EQ(changed_signals(baseline, run(c)), it->second.second) << it->second.first;
    const std::string json = sim_truth_json(c, 0, "x.log");
    const std::string active = json.substr(json.find("\"effects\""), json.find("\"chain\"") - json.find("\"effects\""));
    EXPECT_NE(active.find("\"" + std::string(e.name) + "\": {"), std::string::npos) << json;
  }
}

SimConfig quiet(double rpm, double seconds) {
  SimConfig c;
  c.profile = {{seconds, rpm, rpm}};
  c.chain.noise = {};
  c.chain.tracking_loop.omega_n = 0.0;  // ideal converter: only the effect under test
  return c;
}

TEST(SimEffects, SamplingSkewReachesTheSampledAngleOnlyAndGrowsWithSpeed) {
  const double tau = 2e-5;  // [s]
  std::vector<double> peaks;
  for (const double rpm : {1000.0, 3000.0}) {
    SimConfig c = quiet(rpm, 0.1);
    ASSERT_FALSE(apply_effect_spec(c.chain, "sampling_skew:tau=2e-5"));
    const double omega = c.p_r * rpm * kTwoPi / 60.0;  // [rad/s] resolver electrical
    const double beta = omega * tau;
    // Quadrature remainder (signatures_test) + rounding of both channels to whole
    // counts: a perturbation <= 0.5 sqrt2 counts moves atan2 by <= 0.71 / (A (1 - beta)).
    const double b = std::abs(beta);
    const double tol = 0.5 * b * b * (2.0 + b) / ((1.0 - b) * (1.0 - b)) + 0.71 / (c.amplitude_counts * (1.0 - b));
    double peak = 0.0;
    for (const SimSample& s : run(c)) {
      const double eps_sc = wrap_pi(s.theta - std::atan2(s.sin_counts, s.cos_counts));
      ASSERT_NEAR(eps_sc, sampling_skew_error(c.chain.sampling_skew, s.theta, omega), tol) << s.index;
      // The R/D converter does not see the skew: half a 16-bit LSB.
      ASSERT_NEAR(wrap_pi(s.theta - s.rd_angle), 0.0, 0.5 * quantization_lsb(16) + 1e-12) << s.index;
      peak = std::max(peak, std::abs(eps_sc));
    }
    EXPECT_NEAR(peak, beta, tol);
    peaks.push_back(peak);
  }
  EXPECT_GT(peaks[1], 2.5 * peaks[0]) << "three times the speed, about three times the error";
}

TEST(SimEffects, EccentricityIsOneTimesMechanicalInBothAngles) {
  SimConfig c = quiet(200.0, 0.6);  // two mechanical turns
  ASSERT_FALSE(apply_effect_spec(c.chain, "eccentricity:e=1e-3,phase=0.4"));
  double peak = 0.0;
  for (const SimSample& s : run(c)) {
    const double expected = c.p_r * eccentricity_error(c.chain.eccentricity, s.theta_m);
    ASSERT_NEAR(wrap_pi(s.theta - s.rd_angle), expected, 0.5 * quantization_lsb(16) + 1e-9) << s.index;
    ASSERT_NEAR(wrap_pi(s.theta - std::atan2(s.sin_counts, s.cos_counts)), expected, 0.71 / c.amplitude_counts * 1.01);
    peak = std::max(peak, std::abs(expected));
  }
  EXPECT_NEAR(peak, 3e-3, 1e-5);  // p_r e, reached within the grid
}

/// Clarke + Park (DESIGN 3) of a sample's decoded currents [A].
DqCurrents sample_dq(const SimSample& s, double theta_e) {
  const double i_alpha = s.i_a_ma * 1e-3;
  const double i_beta = (s.i_b_ma - s.i_c_ma) * 1e-3 / std::numbers::sqrt3;
  return {i_alpha * std::cos(theta_e) + i_beta * std::sin(theta_e),
          -i_alpha * std::sin(theta_e) + i_beta * std::cos(theta_e)};
}

// Rounding each phase to 1 mA moves (i_alpha, i_beta) by <= (0.5, 1/sqrt3) mA,
// so a dq value by <= 0.77 mA, and a Fourier amplitude (2/N sum) by <= 1.53 mA.
constexpr double kDqRound = 0.77e-3;    // [A]
constexpr double kRippleRound = 1.53e-3;  // [A]

TEST(SimEffects, MountingOffsetGivesSteadyIdInTheReferenceFrameOnly) {
  SimConfig c = quiet(200.0, 0.2);
  ASSERT_FALSE(apply_effect_spec(c.chain, "mounting_offset:theta_0=0.2"));
  ASSERT_EQ(c.p, c.p_r);  // the drive angle is then the R/D angle itself
  for (const SimSample& s : run(c)) {
    const DqCurrents ref = sample_dq(s, s.theta_e);
    ASSERT_NEAR(ref.d, -c.i_q_cmd * std::sin(0.2), kDqRound) << s.index;
    ASSERT_NEAR(ref.q, c.i_q_cmd * std::cos(0.2), kDqRound) << s.index;
    // Drive frame: rounding plus |I| times half a 16-bit LSB of angle.
    const DqCurrents drive = sample_dq(s, s.rd_angle);
    ASSERT_NEAR(drive.d, 0.0, kDqRound + c.i_q_cmd * 0.5 * quantization_lsb(16)) << s.index;
    ASSERT_NEAR(wrap_pi(s.theta - s.rd_angle), mounting_offset_error(c.chain.mounting_offset, c.p_r, c.p),
                0.5 * quantization_lsb(16) + 1e-9);
  }
}

TEST(SimEffects, CurrentEffectsRippleAtTheirOrders) {
  struct Case {
    const char* spec;
    int order;
  };
  for (const Case& k : {Case{"current_offsets:off_a=0.1,off_b=-0.05", 1}, Case{"current_gain_mismatch:gain_a=0.02", 2},
                        Case{"dead_time:t_d=2e-6", 6}}) {
    // 200 r/min, p = 3: 10 Hz electrical = 200 samples per turn at 2 kHz; 0.5 s = 5 whole turns.
    SimConfig c = quiet(200.0, 0.5);
    ASSERT_FALSE(apply_effect_spec(c.chain, k.spec));
    std::array<std::complex<double>, 8> d{};
    std::array<std::complex<double>, 8> q{};
    const std::vector<SimSample> samples = run(c);
    ASSERT_EQ(samples.size(), 1000U);
    const double n = static_cast<double>(samples.size());
    for (const SimSample& s : samples) {
      const DqCurrents dq = sample_dq(s, s.theta_e);
      for (int h = 1; h < 8; ++h) {
        d[static_cast<std::size_t>(h)] += dq.d * std::polar(2.0 / n, -h * s.theta_e);
        q[static_cast<std::size_t>(h)] += dq.q * std::polar(2.0 / n, -h * s.theta_e);
      }
    }
    // The library's closed-form ripple on i_d / i_q at the effect's order.
    DqCurrents want{};
    if (k.order == 1) want = {current_offsets_ripple_1x(c.chain.current_offsets), current_offsets_ripple_1x(c.chain.current_offsets)};
    if (k.order == 2) {
      const double a = current_gain_mismatch_ripple_2x(c.chain.current_gain_mismatch, c.i_d_cmd, c.i_q_cmd);
      want = {a, a};
    }
    if (k.order == 6) want = dead_time_ripple_6x(c.chain.dead_time, c.i_d_cmd, c.i_q_cmd);
    for (int h = 1; h < 8; ++h) {
      const auto i = static_cast<std::size_t>(h);
      const DqCurrents expect = h == k.order ? want : DqCurrents{};
      EXPECT_NEAR(std::abs(d[i]), expect.d, kRippleRound) << k.spec << " order " << h;
      EXPECT_NEAR(std::abs(q[i]), expect.q, kRippleRound) << k.spec << " order " << h;
    }
    EXPECT_GT(std::max(want.d, want.q), 50.0 * kRippleRound) << k.spec << ": the ripple is well above rounding";
  }
}

TEST(SimEffects, BadEffectParametersNameTheField) {
  SimConfig c = quiet(200.0, 0.01);
  c.chain.eccentricity.e = 1.5;  // only reachable through the struct: the catalog caps it at 0.5
  try {
    BenchSimulator sim(c);
    ADD_FAILURE() << "accepted e = 1.5";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("eccentricity.e"), std::string::npos) << e.what();
  }
  c = quiet(200.0, 0.01);
  c.i_q_cmd = 32.0;  // fits the i16 mA range alone...
  EXPECT_NO_THROW(BenchSimulator{c});
  // ...but k_dt = 0.2 raises a phase's peak by max(cos psi + 0.4 cos 6psi sin psi) - 1 ~ 6.7 %.
  c.chain.dead_time.t_d = 2e-5;
  try {
    BenchSimulator sim(c);
    ADD_FAILURE() << "accepted a clipping current";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("dead time"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resolver
