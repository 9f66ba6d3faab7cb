// The two real recordings of tests/data/corpus (not simulated; see its README)
// read through the shipped example configs (tools/examples/), the way
// resolverd --replay and resolver-model read them (tools/model/log_samples.h
// is the shared input path). Each test says what the recording shows before
// asserting it; the bounds come from the data.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "daemon/app/daemon_config.h"
#include "daemon/core/angles.h"
#include "tools/model/log_samples.h"

namespace resolver {
namespace {

const std::string kRepo = RESOLVER_SOURCE_DIR;

/// True when the angles visit every one of `bins` equal sectors of [0, 2pi).
template <typename Get>
bool covers_the_circle(const std::vector<Sample>& samples, int bins, Get get) {
  std::vector<bool> seen(static_cast<std::size_t>(bins), false);
  for (const Sample& s : samples) seen[static_cast<std::size_t>(get(s) / kTwoPi * bins) % seen.size()] = true;
  return std::all_of(seen.begin(), seen.end(), [](bool b) { return b; });
}

TEST(CorpusExports, MoteusEncoderCalibrationSweep) {
  // What it is: 2119 rows, one mechanical revolution up (1060 rows) and one
  // down (1059), no time column (read at the example's 100 rows/s). The
  // on-board encoder (u16 counts of a mechanical turn) is the sensor, the
  // commanded electrical angle of the 21-pole-pair motor, unwrapped and divided
  // by 21, the reference. Open loop, so the reference lags and cogs: encoder
  // minus reference is a constant offset (the unknown rotor alignment, -2.91 rad
  // in this capture) plus 1.8 deg peak to peak of lag and cogging.
  const DaemonConfig config = load_daemon_config(kRepo + "/tools/examples/moteus_sweep.toml");
  const LogSamples got = read_log_samples(kRepo + "/tests/data/corpus/moteus/encoder_calibration_sweep.csv", nullptr, config);
  const auto& s = got.input.samples;
  ASSERT_EQ(s.size(), 2119U);
  EXPECT_EQ(got.bad_lines, 0);
  EXPECT_EQ(got.problems, 0);
  EXPECT_EQ(got.input.p_r, 1);
  EXPECT_EQ(got.input.p, 21);
  EXPECT_DOUBLE_EQ(s.front().t, 0.0);
  EXPECT_NEAR(s.back().t, 2118.0 / 100.0, 1e-9);  // row rate 100 Hz: 21.18 s
  for (const Sample& x : s) ASSERT_TRUE(x.has_rd && x.has_ref && !x.has_sincos && !x.has_currents);
  // Both angles sweep the whole circle (every 1/16 of it).
  EXPECT_TRUE(covers_the_circle(s, 16, [](const Sample& x) { return x.theta_rd; }));
  EXPECT_TRUE(covers_the_circle(s, 16, [](const Sample& x) { return x.theta_m_ref; }));
  // The reference follows the encoder: after the offset, within the capture's 1.8 deg (0.032 rad)
  // peak to peak; 0.05 rad leaves room and still fails a reference read without the /21.
  double lo = 1e9;
  double hi = -1e9;
  for (const Sample& x : s) {
    const double d = wrap_pi(x.theta_rd - x.theta_m_ref);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  EXPECT_NEAR(0.5 * (lo + hi), -2.91, 0.02);
  EXPECT_LT(hi - lo, 0.05);
}

TEST(CorpusExports, ServoProjectOpticalEncoderChannels) {
  // What it is: 26168 rows over 142.9 s, mostly 4.2 ms apart; the logger
  // pauses about 1.1 s every 5 s and once 7.8 s (33 pauses, found from time:
  // 8132 rows' worth of samples missing). Channels A and B, mapped to sin and
  // cos, are raw ADC counts: A spans 4935..14641, B 9814..15677 (unequal
  // amplitudes and offsets); the example config subtracts their mean (offset =
  // -9774 and -13148, what prepare's "does not circle zero" error suggests), so
  // the pair circles zero. No R/D angle, no reference.
  const DaemonConfig config = load_daemon_config(kRepo + "/tools/examples/servoproject_ab.toml");
  const LogSamples got = read_log_samples(kRepo + "/tests/data/corpus/servoproject/optical_encoder_ab.txt", nullptr, config);
  const auto& s = got.input.samples;
  ASSERT_EQ(s.size(), 26168U);
  EXPECT_EQ(got.bad_lines, 0);
  EXPECT_NEAR(s.back().t - s.front().t, 142.8900, 1e-6);
  double a_lo = 1e9, a_hi = -1e9, b_lo = 1e9, b_hi = -1e9;
  for (const Sample& x : s) {
    ASSERT_TRUE(x.has_sincos && !x.has_rd && !x.has_ref);
    a_lo = std::min(a_lo, x.sin);
    a_hi = std::max(a_hi, x.sin);
    b_lo = std::min(b_lo, x.cos);
    b_hi = std::max(b_hi, x.cos);
  }
  EXPECT_EQ(a_lo, 4935.0 - 9774.0);
  EXPECT_EQ(a_hi, 14641.0 - 9774.0);
  EXPECT_EQ(b_lo, 9814.0 - 13148.0);
  EXPECT_EQ(b_hi, 15677.0 - 13148.0);
  // The pauses are gaps, not clock jumps: time keeps them (142.89 s end to end above), and the notes say so.
  EXPECT_EQ(got.problems, 33);
  EXPECT_EQ(s.back().index, 26167 + 8132);
  ASSERT_FALSE(got.notes.empty());
  EXPECT_NE(std::find_if(got.notes.begin(), got.notes.end(),
                         [](const std::string& n) { return n.find("sample_gap: 33") != std::string::npos; }),
            got.notes.end());
}

}  // namespace
}  // namespace resolver
