// SignalHealthMonitor on synthetic resolver signals with known faults: each
// fault is raised by the damage it names and by nothing else, with a clean
// control beside it. Signals: s = A sin(theta), c = A cos(theta) in ADC counts
// (rounded, as an ADC reports them) plus Gaussian noise, theta_rd = theta.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/health/signal_health.h"

namespace resolver {
namespace {

constexpr double kRate = 2000.0;     // [Hz] default bench sample rate
constexpr int kPr = 3;               // resolver pole pairs
constexpr double kAmplitude = 26000; // [counts] the simulator's default envelope
constexpr double kNoise = 2.0;       // [counts] rms, the simulator's default sigma_sc

struct Bench {
  double rpm = 200.0;           // mechanical
  double seconds = 2.0;
  double amplitude = kAmplitude;
  double noise = kNoise;
  bool reference = true;
  bool rd = true;
  /// Changes sample k (index, theta [rad], in/out sample) after it is built.
  std::function<void(std::int64_t, double, Sample&)> damage;
};

double clamp_adc(double v) { return std::clamp(std::round(v), -32768.0, 32767.0); }

std::vector<Sample> make_samples(const Bench& b, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const auto n = static_cast<std::int64_t>(b.seconds * kRate);
  const double omega_m = b.rpm / 60.0 * kTwoPi;  // [rad/s] mechanical
  std::vector<Sample> out;
  out.reserve(static_cast<std::size_t>(n));
  for (std::int64_t k = 0; k < n; ++k) {
    Sample s;
    s.index = k;
    s.t = static_cast<double>(k) / kRate;
    s.utime = static_cast<std::int64_t>(s.t * 1e6);
    const double theta_m = omega_m * s.t + 0.3;
    const double theta = kPr * theta_m;
    s.has_sincos = true;
    s.sin = clamp_adc(b.amplitude * std::sin(theta) + b.noise * noise(rng));
    s.cos = clamp_adc(b.amplitude * std::cos(theta) + b.noise * noise(rng));
    s.has_rd = b.rd;
    s.theta_rd = wrap_2pi(theta);
    s.has_ref = b.reference;
    s.theta_m_ref = wrap_2pi(theta_m);
    if (b.damage) b.damage(k, theta, s);
    out.push_back(s);
  }
  return out;
}

SignalHealthSummary run(const Bench& b, SignalHealthConfig config = {}) {
  return summarize_signal_health(make_samples(b), config, kPr, kRate);
}

/// The faults seen at all (samples > 0), by name, for readable failures.
std::vector<std::string> seen(const SignalHealthSummary& s) {
  std::vector<std::string> out;
  for (const auto& f : s.faults) {
    if (f.samples > 0) out.emplace_back(fault_name(f.fault));
  }
  return out;
}

TEST(SignalHealth, CleanBenchHasNoFault) {
  for (double rpm : {200.0, 1000.0, 3000.0}) {
    Bench b;
    b.rpm = rpm;
    const SignalHealthSummary s = run(b);
    EXPECT_TRUE(seen(s).empty()) << rpm << " r/min: " << s.describe();
    EXPECT_NEAR(s.amplitude.mean(), kAmplitude, 1.0) << "mean radius = A (noise adds sigma^2/2A, far below a count)";
    EXPECT_EQ(s.events.size(), 0U);
  }
}

TEST(SignalHealth, DeadExcitationIsLossOfSignalOnlyAndSinCosLost) {
  Bench b;
  b.amplitude = 0.0;  // sin = cos = 0 plus ADC noise
  const auto samples = make_samples(b);
  const SignalHealthSummary s = summarize_signal_health(samples, {}, kPr, kRate);
  const auto& los = s.fault(SignalFault::kLossOfSignal);
  EXPECT_EQ(los.samples, s.samples) << s.describe();
  EXPECT_DOUBLE_EQ(los.share, 1.0);
  EXPECT_EQ(los.episodes, 1);
  EXPECT_TRUE(los.active_at_end);
  EXPECT_DOUBLE_EQ(los.first_t, 0.0);
  // LOS says it all: no DOS, LOT or outliers on top of a missing signal.
  EXPECT_EQ(s.fault(SignalFault::kDegradationOfSignal).samples, 0);
  EXPECT_EQ(s.fault(SignalFault::kLossOfTracking).samples, 0);
  EXPECT_EQ(s.fault(SignalFault::kOutliers).samples, 0);
  ASSERT_EQ(s.events.size(), 1U);
  EXPECT_TRUE(s.events[0].started);
  EXPECT_NE(s.events[0].detail.find("below 1638"), std::string::npos) << s.events[0].detail;
  SignalHealthMonitor m({}, kPr, kRate);
  EXPECT_TRUE(m.sincos_lost(samples[10]));
  EXPECT_FALSE(m.sincos_lost(make_samples(Bench{})[10]));
}

TEST(SignalHealth, LossOfSignalInTheMiddleStartsAndEndsOnce) {
  Bench b;
  b.seconds = 3.0;
  b.damage = [](std::int64_t k, double, Sample& s) {
    if (k >= 2000 && k < 4000) s.sin = s.cos = 0.0;  // t = 1 s .. 2 s
  };
  const SignalHealthSummary s = run(b);
  const auto& los = s.fault(SignalFault::kLossOfSignal);
  EXPECT_EQ(los.episodes, 1) << s.describe();
  // Blocks of 0.1 s = 200 samples line up with the damage here, so the count is exact.
  EXPECT_EQ(los.samples, 2000) << s.describe();
  ASSERT_GE(s.events.size(), 2U);
  std::vector<SignalFaultEvent> los_events;
  for (const auto& e : s.events) {
    if (e.fault == SignalFault::kLossOfSignal) los_events.push_back(e);
  }
  ASSERT_EQ(los_events.size(), 2U);
  EXPECT_TRUE(los_events[0].started);
  EXPECT_NEAR(los_events[0].t, 1.0, 1e-9);
  EXPECT_FALSE(los_events[1].started);
  EXPECT_NEAR(los_events[1].t, 2.0, 1e-9);
  EXPECT_FALSE(los.active_at_end);
}

// A CSV export in volts has no DBC range (full_scale = 0): a signal that dies
// mid-run is still a loss of signal, judged against the amplitude it had, and
// the absolute levels (weak, no headroom, clipping) are not judged at all.
TEST(SignalHealth, UnknownFullScaleJudgesLossAgainstTheAmplitudeSeen) {
  SignalHealthConfig unknown;
  unknown.full_scale = 0.0;
  Bench volts;
  volts.amplitude = 1.2;  // [V] a scope channel; with a 16-bit full scale this would be "no signal"
  volts.noise = 0.0005;   // [V] 0.5 mV scope noise
  volts.seconds = 3.0;
  auto damaged = volts;
  damaged.damage = [](std::int64_t k, double, Sample& s) {
    if (k >= 4000) s.sin = s.cos = 0.0;  // dead from t = 2 s
  };
  // make_samples rounds to ADC counts: undo it for volts.
  auto in_volts = [](Bench b) {
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 1.0);
    auto damage = b.damage;
    b.damage = [&, damage, b](std::int64_t k, double theta, Sample& s) {
      s.sin = b.amplitude * std::sin(theta) + b.noise * noise(rng);
      s.cos = b.amplitude * std::cos(theta) + b.noise * noise(rng);
      if (damage) damage(k, theta, s);
    };
    return make_samples(b);
  };
  const SignalHealthSummary clean = summarize_signal_health(in_volts(volts), unknown, kPr, kRate);
  EXPECT_TRUE(seen(clean).empty()) << clean.describe();
  // Control: the same volts against the 16-bit default full scale read as a dead signal.
  const SignalHealthSummary wrong = summarize_signal_health(in_volts(volts), {}, kPr, kRate);
  EXPECT_EQ(wrong.fault(SignalFault::kLossOfSignal).share, 1.0) << wrong.describe();
  const SignalHealthSummary dead = summarize_signal_health(in_volts(damaged), unknown, kPr, kRate);
  const auto& los = dead.fault(SignalFault::kLossOfSignal);
  EXPECT_EQ(los.samples, 2000) << dead.describe();  // blocks of 200 line up with sample 4000
  EXPECT_EQ(los.episodes, 1);
  EXPECT_EQ(dead.fault(SignalFault::kClipping).samples, 0);
}

TEST(SignalHealth, OneOpenChannelIsDegradationNotLoss) {
  Bench b;
  b.damage = [](std::int64_t, double, Sample& s) { s.sin = 0.0; };
  const SignalHealthSummary s = run(b);
  EXPECT_EQ(s.fault(SignalFault::kLossOfSignal).samples, 0) << s.describe();
  EXPECT_GT(s.fault(SignalFault::kDegradationOfSignal).share, 0.9) << s.describe();
}

TEST(SignalHealth, ImbalanceInsideTheBandIsFineBeyondItDegraded) {
  // A real sensor's 15 % gain error is an effect to fit; a channel at 40 % of the other's is a fault.
  for (const auto& [alpha, degraded] : {std::pair{0.05, false}, std::pair{0.15, false}, std::pair{-0.6, true}}) {
    Bench b;
    b.damage = [alpha = alpha](std::int64_t, double theta, Sample& s) {
      s.cos = clamp_adc(kAmplitude * (1.0 + alpha) * std::cos(theta));
    };
    const SignalHealthSummary s = run(b);
    EXPECT_EQ(s.fault(SignalFault::kDegradationOfSignal).share > 0.5, degraded) << alpha << ": " << s.describe();
  }
}

TEST(SignalHealth, SpikesOnASensorWithLargeOffsetsAreNoDegradation) {
  // 15 % and -9 % offsets swing the radius by 35 % of its mean, inside the 50 % band; spikes
  // of 3000 counts (15 %) on sin at 50/s, some near the radius' crest where the running
  // outlier test does not see them, took the plain range to 54-60 % in a fifth of the
  // blocks (signal_health.cpp kSwingTrim). The control: the same sensor with an open
  // cos channel is degraded still.
  std::mt19937 rng(11);
  std::bernoulli_distribution spike(50.0 / kRate);
  std::bernoulli_distribution sign(0.5);
  std::vector<bool> spiked(static_cast<std::size_t>(4.0 * kRate));
  std::vector<double> size(spiked.size());
  for (std::size_t k = 0; k < spiked.size(); ++k) {
    spiked[k] = spike(rng);
    size[k] = sign(rng) ? 3000.0 : -3000.0;
  }
  for (const bool open : {false, true}) {
    Bench b;
    b.seconds = 4.0;
    b.amplitude = 20000.0;
    b.damage = [&, open](std::int64_t k, double theta, Sample& s) {
      const auto i = static_cast<std::size_t>(k);
      const double sin_clean = 20000.0 * (std::sin(theta) + 0.15), cos_clean = 20000.0 * (std::cos(theta) - 0.09);
      s.sin = clamp_adc(sin_clean + (spiked[i] ? size[i] : 0.0));
      s.cos = open ? 0.0 : clamp_adc(cos_clean);
      s.theta_rd = wrap_2pi(std::atan2(sin_clean, cos_clean));  // the converter tracks the sensor's own angle
    };
    const SignalHealthSummary s = run(b);
    if (open) {
      EXPECT_GT(s.fault(SignalFault::kDegradationOfSignal).share, 0.9) << s.describe();
    } else {
      EXPECT_EQ(s.fault(SignalFault::kDegradationOfSignal).samples, 0) << s.describe();
      EXPECT_GT(s.fault(SignalFault::kOutliers).samples, 0) << s.describe();  // the spikes are seen as such
    }
  }
}

TEST(SignalHealth, ASamplesOwnFaultsAreItsImpulseNotTheEpisode) {
  // The live fit counts each sample's faults (pipeline.cpp): an outlier episode lasts from its
  // first impulse to a block without one, but only the impulses are outliers.
  const std::vector<std::int64_t> spikes{500, 520, 2000};
  Bench b;
  b.damage = [&spikes](std::int64_t k, double, Sample& s) {
    if (std::find(spikes.begin(), spikes.end(), k) != spikes.end()) s.sin += 3000.0;
  };
  SignalHealthMonitor m({}, kPr, kRate);
  const auto outlier_bit = static_cast<std::uint8_t>(1U << static_cast<unsigned>(SignalFault::kOutliers));
  std::int64_t flagged = 0, in_episode = 0;
  for (const Sample& s : make_samples(b)) {
    m.add(s);
    const bool own = (m.last_sample_faults() & outlier_bit) != 0;
    EXPECT_EQ(own, std::find(spikes.begin(), spikes.end(), s.index) != spikes.end()) << s.index;
    flagged += own ? 1 : 0;
    in_episode += m.fault(SignalFault::kOutliers).active ? 1 : 0;
  }
  EXPECT_EQ(flagged, 3);
  EXPECT_GT(in_episode, 100);  // the episode: what the live fit counted before
}

TEST(SignalHealth, WeakAmplitudeIsDegradation) {
  Bench b;
  b.amplitude = 0.15 * 32767;  // between LOS (5 %) and the DOS low line (25 %)
  const SignalHealthSummary s = run(b);
  EXPECT_EQ(s.fault(SignalFault::kLossOfSignal).samples, 0);
  EXPECT_DOUBLE_EQ(s.fault(SignalFault::kDegradationOfSignal).share, 1.0) << s.describe();
}

TEST(SignalHealth, ClippingCountsTheClippedSamples) {
  Bench b;
  b.amplitude = 34000;  // beyond full scale on the axes
  const auto samples = make_samples(b);
  std::int64_t clipped = 0;
  for (const Sample& x : samples) clipped += (std::abs(x.sin) >= 32767 || std::abs(x.cos) >= 32767) ? 1 : 0;
  ASSERT_GT(clipped, 0);
  const SignalHealthSummary s = summarize_signal_health(samples, {}, kPr, kRate);
  EXPECT_EQ(s.fault(SignalFault::kClipping).samples, clipped) << s.describe();
  Bench control;
  control.amplitude = 32000;  // 98 % of full scale plus 2 counts of noise: never at the rail
  EXPECT_EQ(run(control).fault(SignalFault::kClipping).samples, 0);
}

TEST(SignalHealth, LossOfTrackingBeyondFiveDegrees) {
  for (const auto& [offset_deg, lot] : {std::pair{2.0, false}, std::pair{10.0, true}}) {
    Bench b;
    b.damage = [off = offset_deg * kPi / 180.0](std::int64_t, double, Sample& s) {
      s.theta_rd = wrap_2pi(s.theta_rd + off);
    };
    const SignalHealthSummary s = run(b);
    EXPECT_EQ(s.fault(SignalFault::kLossOfTracking).share > 0.9, lot) << offset_deg << " deg: " << s.describe();
    EXPECT_EQ(s.fault(SignalFault::kLossOfTracking).samples == 0, !lot);
  }
}

TEST(SignalHealth, StoppedMotor) {
  Bench b;
  b.rpm = 0.0;
  const SignalHealthSummary s = run(b);
  EXPECT_DOUBLE_EQ(s.fault(SignalFault::kStopped).share, 1.0) << s.describe();
  EXPECT_EQ(seen(s), std::vector<std::string>{"stopped"});
  Bench slow;
  slow.rpm = 5.0;  // 0.25 Hz electrical with p_r = 3: slow, not stopped
  EXPECT_EQ(run(slow).fault(SignalFault::kStopped).samples, 0);
}

TEST(SignalHealth, StallsAndLostSamplesDoNotFakeAStop) {
  // A loaded live reader: the sample clock re-anchors after stalls (t jumps 90 ms
  // forward every 50 samples while the counter goes on by one), and bursts of samples
  // are lost (gaps of 20 indices). The motor turns at 200 r/min all along.
  auto samples = make_samples(Bench{});
  std::vector<Sample> damaged;
  double shift = 0.0;
  for (const Sample& x : samples) {
    if (x.index % 100 >= 40 && x.index % 100 < 60) continue;  // lost
    if (x.index % 50 == 0) shift += 0.09;
    Sample y = x;
    y.t += shift;
    damaged.push_back(y);
  }
  const SignalHealthSummary s = summarize_signal_health(damaged, {}, kPr, kRate);
  EXPECT_EQ(s.fault(SignalFault::kStopped).samples, 0) << s.describe();
  EXPECT_EQ(s.fault(SignalFault::kOverspeed).samples, 0) << s.describe();
  // Control: the same damage on a stopped motor is still a stop.
  Bench stopped;
  stopped.rpm = 0.0;
  std::vector<Sample> still;
  for (const Sample& x : make_samples(stopped)) {
    if (x.index % 100 >= 40 && x.index % 100 < 60) continue;
    still.push_back(x);
  }
  EXPECT_GT(summarize_signal_health(still, {}, kPr, kRate).fault(SignalFault::kStopped).share, 0.9);
}

TEST(SignalHealth, OverspeedBeforeAliasingAndWithAnAliasedAngle) {
  // Line pi/4 rad per sample = 5000 r/min at 2 kHz with p_r = 3.
  Bench below;
  below.rpm = 4500;
  EXPECT_EQ(run(below).fault(SignalFault::kOverspeed).samples, 0) << run(below).describe();
  Bench above;
  above.rpm = 10000;  // pi/2 per sample
  EXPECT_DOUBLE_EQ(run(above).fault(SignalFault::kOverspeed).share, 1.0) << run(above).describe();
  // 38000 r/min: 0.95 resolver electrical revolutions per sample (1900 Hz with
  // p_r = 3), so the resolver angle aliases to a slow backwards turn (-0.05 rev
  // per sample, "-2000 r/min"); the mechanical reference (0.32 rev per sample)
  // still resolves it.
  Bench aliased;
  aliased.rpm = 38000;
  const SignalHealthSummary with_ref = run(aliased);
  EXPECT_DOUBLE_EQ(with_ref.fault(SignalFault::kOverspeed).share, 1.0) << with_ref.describe();
  aliased.reference = false;
  EXPECT_EQ(run(aliased).fault(SignalFault::kOverspeed).samples, 0)
      << "without a reference an alias is indistinguishable from a slow turn (documented)";
}

TEST(SignalHealth, OutliersCountedExactlyAndNotInTheNoise) {
  const std::vector<std::int64_t> spikes{500, 1234, 2000, 2001, 3999};
  Bench b;
  b.damage = [&spikes](std::int64_t k, double, Sample& s) {
    if (std::find(spikes.begin(), spikes.end(), k) != spikes.end()) s.sin += 3000.0;
  };
  const SignalHealthSummary s = run(b);
  EXPECT_EQ(s.fault(SignalFault::kOutliers).samples, static_cast<std::int64_t>(spikes.size())) << s.describe();
  EXPECT_EQ(s.fault(SignalFault::kDegradationOfSignal).samples, 0) << "a spike is not a degraded signal";
  EXPECT_EQ(s.fault(SignalFault::kLossOfTracking).samples, 0);
  // Controls: long noisy runs, a speed ramp and an amplitude step raise no
  // outlier beyond the few samples of a level change.
  Bench noisy;
  noisy.seconds = 30.0;
  noisy.noise = 20.0;
  EXPECT_EQ(run(noisy).fault(SignalFault::kOutliers).samples, 0);
  std::vector<Sample> ramp;
  {
    Bench r;
    r.seconds = 4.0;
    ramp = make_samples(r);
    double theta_m = 0.0;
    for (Sample& x : ramp) {
      const double rpm = 200.0 + 250.0 * x.t;  // 200 -> 1200 r/min in 4 s
      theta_m += rpm / 60.0 * kTwoPi / kRate;
      x.sin = std::round(kAmplitude * std::sin(kPr * theta_m));
      x.cos = std::round(kAmplitude * std::cos(kPr * theta_m));
      x.theta_rd = wrap_2pi(kPr * theta_m);
      x.theta_m_ref = wrap_2pi(theta_m);
    }
  }
  EXPECT_EQ(summarize_signal_health(ramp, {}, kPr, kRate).fault(SignalFault::kOutliers).samples, 0);
  Bench step;
  step.damage = [](std::int64_t k, double theta, Sample& x) {
    if (k >= 1500) {
      x.sin = std::round(20000 * std::sin(theta));
      x.cos = std::round(20000 * std::cos(theta));
    }
  };
  EXPECT_LE(run(step).fault(SignalFault::kOutliers).samples, 8) << "a level change costs at most one run of 8";
}

// A real sensor's gain error makes the radius swing with 2 theta by alpha / 2 of the
// amplitude. Through a reversal the rotor lingers, the last 128 samples span a sliver of
// that swing, and the radius's level test (its running median and spread) read the swing's
// slow return as impulsive: every reversal of a 5 % imbalance raised 7-14 outliers, and
// resolverd's windows around it were called faulty ("fix the input and record again").
// The radius's change from the last good sample is what a spike shows.
TEST(SignalHealth, AReversalOfAnImbalancedSensorIsNoOutlierAndASpikeStillIs) {
  for (const double alpha : {0.05, 0.13}) {
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, kNoise);
    std::vector<Sample> v;
    double theta_m = 0.3;
    for (std::int64_t k = 0; k < static_cast<std::int64_t>(7.0 * kRate); ++k) {
      const double t = static_cast<double>(k) / kRate;
      // 1493.7 r/min, down through 0 to -702.9 r/min in 3 s, held (resolver-sim's ramp).
      const double rpm = t < 2.0 ? 1493.7 : t < 5.0 ? 1493.7 - (1493.7 + 702.9) * (t - 2.0) / 3.0 : -702.9;
      theta_m += rpm / 60.0 * kTwoPi / kRate;
      const double theta = kPr * theta_m;
      Sample x;
      x.index = k;
      x.t = t;
      x.utime = static_cast<std::int64_t>(t * 1e6);
      x.has_sincos = true;
      x.sin = clamp_adc(kAmplitude * std::sin(theta) + noise(rng));
      x.cos = clamp_adc(kAmplitude * (1.0 + alpha) * std::cos(theta) + noise(rng));
      x.has_rd = true;
      x.theta_rd = wrap_2pi(theta);
      x.has_ref = true;
      x.theta_m_ref = wrap_2pi(theta_m);
      v.push_back(x);
    }
    const SignalHealthSummary clean = summarize_signal_health(v, {}, kPr, kRate);
    EXPECT_EQ(clean.fault(SignalFault::kOutliers).samples, 0) << "alpha " << alpha << ": " << clean.describe();
    // Control: spikes of 3000 counts (11.5 % of the amplitude), two in the lingering near
    // standstill (the zero crossing is at 4.04 s: sample 8088), are each counted. Not at
    // alpha 13 %: there the angle test (its residual against the running median step) is
    // itself near its threshold 0.15 s after the crossing, and one spike more in its
    // history tips it into a run of 8 (a known limit: that test's history, too, spans a sliver of the
    // distortion where the rotor lingers); and at -703 r/min
    // the swing of a 13 % imbalance hides a 3000-count spike from both tests.
    if (alpha > 0.1) continue;
    const std::vector<std::int64_t> spikes{8100, 8300, 12000};
    for (const std::int64_t k : spikes) v[static_cast<std::size_t>(k)].sin += 3000.0;
    const SignalHealthSummary spiked = summarize_signal_health(v, {}, kPr, kRate);
    EXPECT_EQ(spiked.fault(SignalFault::kOutliers).samples, static_cast<std::int64_t>(spikes.size()))
        << "alpha " << alpha << ": " << spiked.describe();
  }
}

// Issue 25: a looped replay joins the log's end to its start; the angle jumps
// there, and every pass raised "outliers started ... 7 impulsive sample(s)" and
// "outliers ended 0.000 s into the input (sample 0)" on a clean log.
TEST(SignalHealth, ALoopJointIsNoFaultAndAnEndSaysWhen) {
  Bench b;
  b.rpm = 207.0;  // 20.7 electrical turns in 2 s: the end is 0.3 turn from the start
  std::vector<Sample> pass = make_samples(b);
  // A ramp 200 -> 1000 r/min, as resolver-sim --profile "200-1000:2": the joint is a
  // speed step too.
  double theta_m = 0.3;
  for (Sample& x : pass) {
    theta_m += (200.0 + 400.0 * x.t) / 60.0 * kTwoPi / kRate;
    x.sin = std::round(kAmplitude * std::sin(kPr * theta_m));
    x.cos = std::round(kAmplitude * std::cos(kPr * theta_m));
    x.theta_rd = wrap_2pi(kPr * theta_m);
    x.theta_m_ref = wrap_2pi(theta_m);
  }
  auto looped = [&](bool tell) {
    SignalHealthMonitor m({}, kPr, kRate);
    std::vector<SignalFaultEvent> events;
    for (int k = 0; k < 3; ++k) {
      if (k > 0 && tell) m.new_pass();
      for (Sample s : pass) {
        s.index += k * static_cast<std::int64_t>(pass.size());  // index and time go on across passes
        s.t += k * b.seconds;
        m.add(s);
        for (const auto& e : m.take_events()) events.push_back(e);
      }
    }
    m.finish();
    for (const auto& e : m.take_events()) events.push_back(e);
    return std::make_pair(m.fault(SignalFault::kOutliers).samples, events);
  };
  const auto [told, told_events] = looped(true);
  EXPECT_EQ(told, 0);
  EXPECT_TRUE(told_events.empty()) << fault_name(told_events.front().fault);
  // Control: without new_pass() the joints read as impulses, and each end of the
  // outlier fault is placed at the block's start, not at 0 s / sample 0.
  const auto [blind, blind_events] = looped(false);
  EXPECT_GT(blind, 0);
  ASSERT_FALSE(blind_events.empty());
  for (const auto& e : blind_events) {
    EXPECT_GT(e.t, 1.9) << (e.started ? "start" : "end");
    EXPECT_GT(e.index, 3000) << (e.started ? "start" : "end");
  }
}

TEST(SignalHealth, AmplitudeWindowIsSinceTheLastTake) {
  SignalHealthMonitor m({}, kPr, kRate);
  Bench b;
  b.noise = 0.0;
  for (const Sample& s : make_samples(b)) m.add(s);
  const AmplitudeStats w = m.take_amplitude_window();
  EXPECT_EQ(w.n, 4000);
  EXPECT_NEAR(w.mean(), kAmplitude, 1.0);  // rounding to counts: within a count
  EXPECT_LE(w.max - w.min, 2.0);
  EXPECT_EQ(m.take_amplitude_window().n, 0);
  EXPECT_EQ(m.amplitude_total().n, 4000);
}

TEST(SignalHealth, ThresholdsComeFromTheConfig) {
  Bench b;
  b.amplitude = 0.15 * 32767;
  SignalHealthConfig c;
  c.degradation_low_fraction = 0.1;  // now 15 % is inside the band
  EXPECT_EQ(run(b, c).fault(SignalFault::kDegradationOfSignal).samples, 0);
  c.full_scale = 2047;  // a 12-bit ADC: 4915 counts are far above its full scale
  EXPECT_GT(run(b, c).fault(SignalFault::kClipping).samples, 0);
}

}  // namespace
}  // namespace resolver
