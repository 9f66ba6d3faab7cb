// The simulator honours every registry effect: each spec changes exactly the
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
#include "daemon/core/effects/current_gain_mismatch.h"
#include "daemon/core/effects/current_offsets.h"
#include "daemon/core/effects/dead_time.h"
#include "daemon/core/effects/eccentricity.h"
#include "daemon/core/effects/mounting_offset.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/effects/sampling_skew.h"
#include "tests/unit/sim/sim_test_support.h"
#include "tools/sim/bench_simulator.h"
#include "tools/sim/sim_truth.h"

namespace resolver {
namespace {

using test::changed_signals;
using test::kCurrents;
using test::kRd;
using test::kSinCos;
using test::quiet;
using test::run;

TEST(SimEffects, EverySpecChangesExactlyTheSignalsItReaches) {
  // One visible spec per registry effect, and the signals it must (and must only) change.
  const std::map<std::string, std::pair<std::string, unsigned>> table{
      {"amplitude_imbalance", {"amplitude_imbalance:alpha=0.01", kSinCos | kRd}},
      {"quadrature", {"quadrature:beta=0.01", kSinCos | kRd}},
      {"offsets", {"offsets:o_s=0.01", kSinCos | kRd}},
      {"harmonics", {"harmonics:k3=0.005", kSinCos | kRd}},
      // Both channels x (1 + g t): the radius, never the angle (the converter's atan2 and
      // its loop's error signal keep their zero; 0.1 s reaches 1e-3 = 26 counts).
      {"envelope_drift", {"envelope_drift:g=0.01", kSinCos}},
      {"sampling_skew", {"sampling_skew:tau=2e-5", kSinCos}},  // the DSP's sampling, not the converter
      {"channel_delay", {"channel_delay:tau=2e-5", kSinCos | kRd}},  // the analog path: both see it
      {"tracking_loop", {"tracking_loop:omega_n=1000", kRd}},
      {"quantization", {"quantization:rd_bits=12", kRd}},
      {"backlash", {"backlash:h=0.01", kSinCos | kRd}},  // the reference is on the other side of the play
      {"eccentricity", {"eccentricity:e=1e-3,phase=0.4", kSinCos | kRd}},
      {"mechanical_harmonics", {"mechanical_harmonics:a2=1e-3", kSinCos | kRd}},
      {"mounting_offset", {"mounting_offset:theta_0=0.1", kSinCos | kRd | kCurrents}},
      {"delay", {"delay:d=1e-3", kSinCos | kRd}},  // the resolver is late, the reference and currents are not
      {"current_offsets", {"current_offsets:off_a=0.1,off_b=-0.05", kCurrents}},
      {"current_gain_mismatch", {"current_gain_mismatch:gain_a=0.02", kCurrents}},
      {"dead_time", {"dead_time:t_d=2e-6", kCurrents}},
      {"noise", {"noise:sigma_sc=5", kSinCos}},
      {"outliers", {"outliers:rate=200,size=3000", kSinCos}},
      {"current_outliers", {"current_outliers:rate=200,size=5", kCurrents}},
  };
  SimConfig base;  // default chain: noise and tracking loop on, same seed for every run
  // A hold and a ramp: at constant speed a type-II loop tracks an ideal resolver
  // without error, under acceleration it lags by a / omega_n^2.
  base.profile = {{0.05, 1000.0, 1000.0}, {0.05, 1000.0, 2000.0}};
  const std::vector<SimSample> baseline = run(base);
  // Outliers draw from the simulator's one random engine after the noise of each
  // sample, so with noise on they re-deal every later noise draw (currents
  // included: same statistics, other values). Their own reach is checked on a
  // noise-free base, where nothing else draws.
  SimConfig noise_free = base;
  noise_free.chain.set("noise", "sigma_sc", 0.0);
  noise_free.chain.set("noise", "sigma_i", 0.0);
  const std::vector<SimSample> noise_free_baseline = run(noise_free);
  for (const Effect* e : effect_registry()) {
    const auto it = table.find(std::string(e->name()));
    ASSERT_NE(it, table.end()) << "add a spec for the new registry effect " << e->name();
    const bool draws = e->name() == "outliers" || e->name() == "current_outliers";
    SimConfig c = draws ? noise_free : base;
    ASSERT_NO_THROW(c.chain.apply_spec(it->second.first));
    EXPECT_EQ(changed_signals(draws ? noise_free_baseline : baseline, run(c)), it->second.second) << it->second.first;
    const std::string json = sim_truth_json(c, 0, "x.log");
    const std::string active = json.substr(json.find("\"effects\""), json.find("\"chain\"") - json.find("\"effects\""));
    EXPECT_NE(active.find("\"" + std::string(e->name()) + "\": {"), std::string::npos) << json;
  }
}

TEST(SimEffects, SamplingSkewReachesTheSampledAngleOnlyAndGrowsWithSpeed) {
  const double tau = 2e-5;  // [s]
  std::vector<double> peaks;
  for (const double rpm : {1000.0, 3000.0}) {
    SimConfig c = quiet(rpm, 0.1);
    c.chain.set("sampling_skew", "tau", tau);
    const double omega = c.p_r * rpm * kTwoPi / 60.0;  // [rad/s] resolver electrical
    const double beta = omega * tau;
    // Quadrature remainder (signatures_test) + rounding of both channels to whole
    // counts: a perturbation <= 0.5 sqrt2 counts moves atan2 by <= 0.71 / (A (1 - beta)).
    const double b = std::abs(beta);
    const double tol = 0.5 * b * b * (2.0 + b) / ((1.0 - b) * (1.0 - b)) + 0.71 / (c.amplitude_counts * (1.0 - b));
    double peak = 0.0;
    for (const SimSample& s : run(c)) {
      const double eps_sc = wrap_pi(s.theta - std::atan2(s.sin_counts, s.cos_counts));
      ASSERT_NEAR(eps_sc, sampling_skew_error({{"tau", tau}}, s.theta, omega), tol) << s.index;
      // The R/D converter does not see the skew: half a 16-bit LSB.
      ASSERT_NEAR(wrap_pi(s.theta - s.rd_angle), 0.0, 0.5 * quantization_lsb(16) + 1e-12) << s.index;
      peak = std::max(peak, std::abs(eps_sc));
    }
    EXPECT_NEAR(peak, beta, tol);
    peaks.push_back(peak);
  }
  EXPECT_GT(peaks[1], 2.5 * peaks[0]) << "three times the speed, about three times the error";
}

TEST(SimEffects, EnvelopeDriftScalesBothChannelsInTimeAndNoAngle) {
  // Both channels x (1 + g t), t from the first sample (envelope_drift.h): the radius in
  // counts follows A (1 + g t), the sampled angle and the R/D angle stay at the floor.
  // Bounds: rounding each channel to whole counts moves the radius by <= 0.5 sqrt2
  // counts and atan2 by <= 0.71 / (A (1 - |g| T)); the R/D angle by half a 16-bit LSB.
  for (const double g : {1e-3, -1e-3}) {
    SimConfig c = quiet(200.0, 3.0);
    c.chain.set("envelope_drift", "g", g);
    const double a = c.amplitude_counts;
    double first = 0.0, last = 0.0;
    for (const SimSample& s : run(c)) {
      const double t = static_cast<double>(s.index) / c.sample_rate_hz;
      const double radius = std::hypot(static_cast<double>(s.sin_counts), static_cast<double>(s.cos_counts));
      ASSERT_NEAR(radius, a * (1.0 + g * t), 0.5 * std::numbers::sqrt2 + 1e-9) << "g=" << g << " t=" << t;
      ASSERT_NEAR(wrap_pi(s.theta - std::atan2(s.sin_counts, s.cos_counts)), 0.0, 0.71 / (a * (1.0 - 3.0 * std::abs(g))))
          << "g=" << g << " t=" << t;
      ASSERT_NEAR(wrap_pi(s.theta - s.rd_angle), 0.0, 0.5 * quantization_lsb(16) + 1e-12) << "g=" << g << " t=" << t;
      (s.index == 0 ? first : last) = radius;
    }
    // Over the 3 s the radius moved by 3 g A = 78 counts, far above the rounding.
    EXPECT_NEAR(last - first, 3.0 * g * a, 2.0) << "g=" << g;
  }
}

TEST(SimEffects, EccentricityIsOneTimesMechanicalInBothAngles) {
  SimConfig c = quiet(200.0, 0.6);  // two mechanical turns
  c.chain.apply_spec("eccentricity:e=1e-3,phase=0.4");
  const EccentricityParams ecc(c.chain.of(eccentricity_effect()));
  double peak = 0.0;
  for (const SimSample& s : run(c)) {
    const double expected = c.p_r * eccentricity_error(ecc, s.theta_m);
    ASSERT_NEAR(wrap_pi(s.theta - s.rd_angle), expected, 0.5 * quantization_lsb(16) + 1e-9) << s.index;
    ASSERT_NEAR(wrap_pi(s.theta - std::atan2(s.sin_counts, s.cos_counts)), expected, 0.71 / c.amplitude_counts * 1.01);
    peak = std::max(peak, std::abs(expected));
  }
  EXPECT_NEAR(peak, 3e-3, 1e-5);  // p_r e, reached within the grid
}

using test::sample_dq;

// Rounding each phase to 1 mA moves (i_alpha, i_beta) by <= (0.5, 1/sqrt3) mA,
// so a dq value by <= 0.77 mA, and a Fourier amplitude (2/N sum) by <= 1.53 mA.
constexpr double kDqRound = 0.77e-3;    // [A]
constexpr double kRippleRound = 1.53e-3;  // [A]

TEST(SimEffects, MountingOffsetGivesSteadyIdInTheReferenceFrameOnly) {
  SimConfig c = quiet(200.0, 0.2);
  c.chain.apply_spec("mounting_offset:theta_0=0.2");
  ASSERT_EQ(c.p, c.p_r);  // the drive angle is then the R/D angle itself
  for (const SimSample& s : run(c)) {
    const DqCurrents ref = sample_dq(s, s.theta_e);
    ASSERT_NEAR(ref.d, -c.i_q_cmd * std::sin(0.2), kDqRound) << s.index;
    ASSERT_NEAR(ref.q, c.i_q_cmd * std::cos(0.2), kDqRound) << s.index;
    // Drive frame: rounding plus |I| times half a 16-bit LSB of angle.
    const DqCurrents drive = sample_dq(s, s.rd_angle);
    ASSERT_NEAR(drive.d, 0.0, kDqRound + c.i_q_cmd * 0.5 * quantization_lsb(16)) << s.index;
    ASSERT_NEAR(wrap_pi(s.theta - s.rd_angle), mounting_offset_error({{"theta_0", 0.2}}, c.p_r, c.p),
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
    ASSERT_NO_THROW(c.chain.apply_spec(k.spec));
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
    // The library's closed-form ripple on i_d / i_q at the effect's order, for the values the spec set.
    const ChainValues& v = c.chain;
    DqCurrents want{};
    if (k.order == 1) {
      const CurrentOffsetsParams off(v.of(current_offsets_effect()));
      want = {current_offsets_ripple_1x(off), current_offsets_ripple_1x(off)};
    }
    if (k.order == 2) {
      const CurrentGainMismatchParams g(v.of(current_gain_mismatch_effect()));
      const double a = current_gain_mismatch_ripple_2x(g, c.i_d_cmd, c.i_q_cmd);
      want = {a, a};
    }
    if (k.order == 6) want = dead_time_ripple_6x(DeadTimeParams(v.of(dead_time_effect())), c.i_d_cmd, c.i_q_cmd);
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
  // Out of range: refused when set (ChainValues), naming the parameter; the simulator never sees it.
  try {
    c.chain.set("eccentricity", "e", 1.5);
    ADD_FAILURE() << "accepted e = 1.5";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'e' of eccentricity"), std::string::npos) << e.what();
  }
  // In range one by one but not as a whole: the seen angle would turn back
  // (sum n |a_n| = 0.4 + 2 x 0.4 >= 1); the simulator refuses it naming the effect.
  c.chain.set("mechanical_harmonics", "a1", 0.4);
  c.chain.set("mechanical_harmonics", "a2", 0.4);
  try {
    BenchSimulator sim(c);
    ADD_FAILURE() << "accepted a non-monotone seen angle";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mechanical_harmonics"), std::string::npos) << e.what();
  }
  // A drifting envelope gain is checked over the whole run, not at its start: 1 + g t
  // reaches 1.3 after 30 s (33800 counts: clips) and 0 after 100 s (reverses the envelopes).
  c = quiet(200.0, 30.0);
  c.chain.set("envelope_drift", "g", 0.01);
  try {
    BenchSimulator sim(c);
    ADD_FAILURE() << "accepted envelopes that clip at the end of the run";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("over the whole run"), std::string::npos) << e.what();
  }
  c = quiet(200.0, 120.0);
  c.chain.set("envelope_drift", "g", -0.01);
  try {
    BenchSimulator sim(c);
    ADD_FAILURE() << "accepted envelopes whose gain goes through zero";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("reversed"), std::string::npos) << e.what();
  }
  c = quiet(200.0, 0.01);
  c.i_q_cmd = 32.0;  // fits the i16 mA range alone...
  EXPECT_NO_THROW(BenchSimulator{c});
  // ...but k_dt = 0.2 raises a phase's peak by max(cos psi + 0.4 cos 6psi sin psi) - 1 ~ 6.7 %.
  c.chain.set("dead_time", "t_d", 2e-5);
  try {
    BenchSimulator sim(c);
    ADD_FAILURE() << "accepted a clipping current";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("dead time"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resolver
