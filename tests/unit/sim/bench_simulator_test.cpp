// The simulator's samples and frames, decoded by hand from the bytes (docs/ARCHITECTURE.md §4)
// with an independent bitwise CRC, against the physics they must carry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/phase_currents.h"
#include "daemon/core/effects/quantization.h"
#include "tools/sim/bench_simulator.h"

namespace resolver {
namespace {

/// CRC-8 SAE J1850 bit by bit (poly 0x1D, init 0xFF, xorout 0xFF) over bytes 0..6 and the ID's low byte.
std::uint8_t reference_crc(const CanFrame& f) {
  std::uint8_t crc = 0xFF;
  const auto feed = [&](std::uint8_t byte) {
    crc ^= byte;
    for (int b = 0; b < 8; ++b) crc = (crc & 0x80U) ? static_cast<std::uint8_t>((crc << 1) ^ 0x1D) : static_cast<std::uint8_t>(crc << 1);
  };
  for (int i = 0; i < 7; ++i) feed(f.data[static_cast<std::size_t>(i)]);
  feed(static_cast<std::uint8_t>(f.id & 0xFF));
  return static_cast<std::uint8_t>(crc ^ 0xFF);
}
std::uint16_t u16(const CanFrame& f, int at) {
  return static_cast<std::uint16_t>(f.data[static_cast<std::size_t>(at)] | (f.data[static_cast<std::size_t>(at) + 1] << 8));
}
std::int16_t i16(const CanFrame& f, int at) { return static_cast<std::int16_t>(u16(f, at)); }
std::uint32_t u32(const CanFrame& f, int at) {
  return static_cast<std::uint32_t>(u16(f, at)) | (static_cast<std::uint32_t>(u16(f, at + 2)) << 16);
}

SimConfig quiet_config(double seconds, double rpm) {
  SimConfig c;
  c.profile = {{seconds, rpm, rpm}};
  c.chain.set("noise", "sigma_sc", 0.0);  // noise off: values are exact up to rounding
  c.chain.set("noise", "sigma_i", 0.0);
  return c;
}

TEST(SimBenchSimulator, TotalSamplesFollowTheProfile) {
  SimConfig c = quiet_config(0.5, 200.0);
  c.profile.push_back({0.25, 200.0, 400.0});
  const BenchSimulator sim(c);
  EXPECT_EQ(sim.total_samples(), 1500U);  // 0.75 s at 2 kHz
  BenchSimulator run(c);
  SimSample s{};
  std::uint64_t n = 0;
  while (run.next(s)) ++n;
  EXPECT_EQ(n, 1500U);
  EXPECT_FALSE(run.next(s));
}

TEST(SimBenchSimulator, FramesDecodeByHandToTheSample) {
  SimConfig c = quiet_config(0.3, 200.0);
  c.chain.set("amplitude_imbalance", "alpha", 0.003);
  c.iface = "vcan0";
  BenchSimulator sim(c);
  SimSample s{};
  std::vector<CanFrame> frames;
  int info_frames = 0;
  while (sim.next(s)) {
    frames.clear();
    sim.append_frames(s, frames);
    ASSERT_GE(frames.size(), 3U);
    for (const CanFrame& f : frames) {
      ASSERT_EQ(f.len, 8);
      ASSERT_FALSE(f.extended);
      ASSERT_EQ(f.data[7], reference_crc(f)) << std::hex << f.id;
      ASSERT_EQ(f.iface_name(), "vcan0");
    }
    const CanFrame& rs = frames[0];
    ASSERT_EQ(rs.id, 0x100U);
    EXPECT_EQ(rs.timestamp_us, s.t_us);
    EXPECT_EQ(rs.data[0], s.counter);
    EXPECT_EQ(i16(rs, 1), s.sin_counts);
    EXPECT_EQ(i16(rs, 3), s.cos_counts);
    EXPECT_EQ(u16(rs, 5), s.rd_counts);
    const CanFrame& pc = frames[1];
    ASSERT_EQ(pc.id, 0x101U);
    EXPECT_EQ(pc.timestamp_us, s.t_us + 1);
    EXPECT_EQ(pc.data[0], s.counter);
    EXPECT_EQ(i16(pc, 1), s.i_a_ma);
    EXPECT_EQ(i16(pc, 3), s.i_b_ma);
    EXPECT_EQ(i16(pc, 5), s.i_c_ma);
    const CanFrame& ra = frames[2];
    ASSERT_EQ(ra.id, 0x102U);
    EXPECT_EQ(ra.timestamp_us, s.t_us + 2);
    EXPECT_EQ(ra.data[0], s.counter);
    EXPECT_EQ(u32(ra, 1), s.ref_counts);
    EXPECT_EQ(u16(ra, 5), 0U);
    if (frames.size() == 4) {
      const CanFrame& bi = frames[3];
      ASSERT_EQ(bi.id, 0x1F0U);
      EXPECT_EQ(bi.timestamp_us, s.t_us + 3);
      EXPECT_EQ(bi.data[0], 1);
      EXPECT_EQ(bi.data[1], 3);
      EXPECT_EQ(bi.data[2], 3);
      EXPECT_EQ(bi.data[3], 16);
      EXPECT_EQ(u16(bi, 4), 2000);
      EXPECT_EQ(bi.data[6], 0);
      EXPECT_EQ(s.index % 200, 0U) << "BENCH_INFO every 100 ms = 200 samples at 2 kHz";
      ++info_frames;
    }
    // Counter and time stamps.
    EXPECT_EQ(s.counter, static_cast<std::uint8_t>(s.index % 256));
    EXPECT_EQ(s.t_us, c.start_time_us + static_cast<std::int64_t>(s.index) * 500);
    // The physics in the bytes: envelopes with imbalance (noise off -> rounding only).
    const double theta = s.theta;
    EXPECT_NEAR(s.sin_counts, c.amplitude_counts * std::sin(theta), 0.5 + 1e-9);
    EXPECT_NEAR(s.cos_counts, c.amplitude_counts * (1.0 + 0.003) * std::cos(theta), 0.5 + 1e-9);
    // Currents: ideal control at the true theta_e, 1 mA/bit.
    const PhaseCurrents i = ideal_phase_currents(c.i_d_cmd, c.i_q_cmd, s.theta_e);
    EXPECT_NEAR(s.i_a_ma, 1000.0 * i.a, 0.5 + 1e-9);
    EXPECT_NEAR(s.i_b_ma, 1000.0 * i.b, 0.5 + 1e-9);
    EXPECT_NEAR(s.i_c_ma, 1000.0 * i.c, 0.5 + 1e-9);
    // Reference angle: 2^32 counts per mechanical turn; rounding <= half a count.
    EXPECT_NEAR(wrap_pi(static_cast<double>(s.ref_counts) / 4294967296.0 * kTwoPi - s.theta_m), 0.0, 1e-9);
    EXPECT_DOUBLE_EQ(s.rd_angle, static_cast<double>(s.rd_counts) * kTwoPi / 65536.0);
    // R/D angle: Hanselman eq. 5 through a loop that is transparent at 200 r/min
    // (|1 - H(j 2w)| ~ 1.8e-3, see bench_simulator.h), plus half a 16-bit LSB, plus the
    // O(alpha^2) terms (<= alpha^2/2).
    const double eps = wrap_pi(theta - s.rd_angle);
    const double tol = 0.5 * quantization_lsb(16) + 0.5 * 0.003 * 0.003 + 0.0015 * 2e-3;
    EXPECT_NEAR(eps, 0.0015 * std::sin(2.0 * theta), tol) << s.index;
  }
  EXPECT_EQ(info_frames, 3);  // at 0, 100, 200 ms of a 300 ms run
}

TEST(SimBenchSimulator, NoReferenceMeansTwoFramesPerSample) {
  SimConfig c = quiet_config(0.01, 100.0);
  c.reference = false;
  BenchSimulator sim(c);
  SimSample s{};
  std::vector<CanFrame> frames;
  while (sim.next(s)) sim.append_frames(s, frames);
  // 20 samples x 2 frames + 1 BENCH_INFO at t = 0.
  EXPECT_EQ(frames.size(), 41U);
  for (const CanFrame& f : frames) EXPECT_NE(f.id, 0x102U);
}

TEST(SimBenchSimulator, TrueAnglesFollowTheProfile) {
  SimConfig c = quiet_config(0.5, 300.0);
  c.profile.push_back({0.5, 300.0, 900.0});
  c.p_r = 2;
  c.p = 4;
  c.theta_m0 = 1.0;
  BenchSimulator sim(c);
  SimSample s{};
  AngleUnwrapper unwrap;
  double start = 0.0;
  while (sim.next(s)) {
    const double continuous = unwrap.update(s.theta_m);
    if (s.index == 0) start = continuous;
    const double t = static_cast<double>(s.index) / 2000.0;
    // Analytic angle of a 300 r/min hold then a 300 -> 900 r/min ramp.
    const double w0 = 300.0 * kTwoPi / 60.0;
    const double expect = t <= 0.5 ? w0 * t : w0 * 0.5 + w0 * (t - 0.5) + 0.5 * (2.0 * w0 / 0.5) * (t - 0.5) * (t - 0.5);
    ASSERT_NEAR(continuous - start, expect, 1e-9) << t;
    ASSERT_NEAR(wrap_pi(s.theta - 2.0 * s.theta_m), 0.0, 1e-9);
    ASSERT_NEAR(wrap_pi(s.theta_e - 4.0 * s.theta_m), 0.0, 1e-9);
    ASSERT_NEAR(s.omega_m, t <= 0.5 ? w0 : w0 + (2.0 * w0) * (t - 0.5) / 0.5, 1e-9);
  }
  EXPECT_NEAR(start, 1.0, 1e-12);
}

std::vector<CanFrame> run_all(const SimConfig& c) {
  BenchSimulator sim(c);
  SimSample s{};
  std::vector<CanFrame> frames;
  while (sim.next(s)) sim.append_frames(s, frames);
  return frames;
}

bool same_frames(const std::vector<CanFrame>& a, const std::vector<CanFrame>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].id != b[i].id || a[i].timestamp_us != b[i].timestamp_us || a[i].data != b[i].data) return false;
  }
  return true;
}

TEST(SimBenchSimulator, SameSeedSameOutput) {
  SimConfig c;  // default chain: noise and tracking loop on
  c.profile = {{0.2, 500.0, 500.0}};
  c.chain.set("quadrature", "beta", 0.002);
  const auto a = run_all(c);
  const auto b = run_all(c);
  EXPECT_TRUE(same_frames(a, b));
  c.seed = 2;
  EXPECT_FALSE(same_frames(a, run_all(c))) << "the noise must depend on the seed";
}

TEST(SimBenchSimulator, NoiseHasTheRequestedSigma) {
  SimConfig c;
  c.profile = {{2.0, 200.0, 200.0}};
  c.chain.set("noise", "sigma_sc", 3.0);  // [counts]
  c.chain.set("noise", "sigma_i", 0.05);   // [A]
  BenchSimulator sim(c);
  SimSample s{};
  double sum_sq_s = 0.0;
  double sum_sq_i = 0.0;
  int n = 0;
  while (sim.next(s)) {
    const double ds = s.sin_counts - c.amplitude_counts * std::sin(s.theta);
    const double di = s.i_a_ma - 1000.0 * ideal_phase_currents(c.i_d_cmd, c.i_q_cmd, s.theta_e).a;
    sum_sq_s += ds * ds;
    sum_sq_i += di * di;
    ++n;
  }
  // Rounding to whole counts / mA adds variance 1/12; 5-sigma bound on a sample sd of n = 4000.
  const double sd_s = std::sqrt(sum_sq_s / n);
  const double sd_i = std::sqrt(sum_sq_i / n);
  EXPECT_NEAR(sd_s, std::sqrt(9.0 + 1.0 / 12.0), 5.0 * 3.0 / std::sqrt(2.0 * n));
  EXPECT_NEAR(sd_i, std::sqrt(50.0 * 50.0 + 1.0 / 12.0), 5.0 * 50.0 / std::sqrt(2.0 * n));
}

TEST(SimBenchSimulator, RdBitsComeFromEitherPlace) {
  SimConfig a = quiet_config(0.01, 200.0);
  a.chain.set("quantization", "rd_bits", 12);
  EXPECT_EQ(BenchSimulator(a).config().rd_bits, 12);
  SimConfig b = quiet_config(0.01, 200.0);
  b.rd_bits = 10;
  BenchSimulator sim(b);
  EXPECT_EQ(sim.config().chain.get("quantization", "rd_bits"), 10.0);
  SimSample s{};
  while (sim.next(s)) ASSERT_EQ(s.rd_counts % 64, 0) << "10 bits: the low 6 bits are zero";
  SimConfig both = b;
  both.chain.set("quantization", "rd_bits", 12);
  EXPECT_THROW(BenchSimulator{both}, std::invalid_argument);
}

void expect_invalid(SimConfig c, std::string_view field) {
  try {
    BenchSimulator sim(std::move(c));
    ADD_FAILURE() << "accepted a bad " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(SimBenchSimulator, BadConfigsNameTheField) {
  SimConfig c = quiet_config(0.1, 200.0);
  SimConfig bad = c;
  bad.p_r = 0;
  expect_invalid(bad, "p_r");
  bad = c;
  bad.sample_rate_hz = 2000.5;
  expect_invalid(bad, "sample_rate_hz");
  bad = c;
  bad.amplitude_counts = 40000;
  expect_invalid(bad, "amplitude_counts");
  bad = c;
  bad.amplitude_counts = 32000;
  bad.chain.set("amplitude_imbalance", "alpha", 0.05);  // cos peak 33600 counts: clips
  expect_invalid(bad, "amplitude_counts");
  bad = c;
  bad.i_q_cmd = 40.0;
  expect_invalid(bad, "i_q_cmd");
  bad = c;
  bad.profile = {{0.0, 200.0, 200.0}};
  expect_invalid(bad, "segment 1");
}

}  // namespace
}  // namespace resolver
