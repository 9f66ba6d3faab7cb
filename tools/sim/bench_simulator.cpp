#include "tools/sim/bench_simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/angles.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/phase_currents.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/decode/bench_layout.h"

namespace resolver {

SensorChainConfig default_sim_chain() {
  SensorChainConfig chain;
  chain.tracking_loop.omega_n = 3000.0;  // [rad/s] see the header
  chain.tracking_loop.zeta = 0.7;
  chain.noise.sigma_sc = 2.0;  // [counts]
  chain.noise.sigma_i = 0.02;  // [A]
  return chain;
}

namespace {

constexpr std::int64_t kBenchInfoPeriodUs = 100000;  // 10 Hz (DESIGN 4)
constexpr double kCurrentFullScale = 32767.0 * bench::kCurrentAmpsPerBit;  // [A] i16 at 1 mA/bit

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

/// Makes rd_bits and chain.quantization.rd_bits one value (see SimConfig::rd_bits).
void reconcile_rd_bits(SimConfig& c) {
  const int from_chain = c.chain.quantization.rd_bits;
  const int dflt = Quantization::kMaxBits;
  if (from_chain != dflt && c.rd_bits != dflt && from_chain != c.rd_bits) {
    throw std::invalid_argument(fmt::format(
        "SimConfig: rd_bits = {} but chain.quantization.rd_bits = {}; they are the same R/D resolution, set one "
        "(--rd-bits or --effect quantization:rd_bits=N)",
        c.rd_bits, from_chain));
  }
  const int bits = from_chain != dflt ? from_chain : c.rd_bits;
  c.rd_bits = bits;
  c.chain.quantization.rd_bits = bits;
}

SimConfig validated(SimConfig c) {
  require(c.p_r >= 1 && c.p_r <= 255, fmt::format("SimConfig p_r (--p-r) = {}: resolver pole pairs must be 1..255 (u8 in BENCH_INFO)", c.p_r));
  require(c.p >= 1 && c.p <= 255, fmt::format("SimConfig p (--p) = {}: motor pole pairs must be 1..255 (u8 in BENCH_INFO)", c.p));
  reconcile_rd_bits(c);
  require(c.rd_bits >= Quantization::kMinBits && c.rd_bits <= Quantization::kMaxBits,
          fmt::format("SimConfig rd_bits (--rd-bits) = {}: R/D resolution must be 1..16 bits (u16 rd_angle field)", c.rd_bits));
  require(c.sample_rate_hz >= 1.0 && c.sample_rate_hz <= 65535.0 && c.sample_rate_hz == std::round(c.sample_rate_hz),
          fmt::format("SimConfig sample_rate_hz (--sample-rate) = {}: must be a whole number of Hz in 1..65535 (u16 in BENCH_INFO)",
                      c.sample_rate_hz));
  require(c.amplitude_counts > 0.0 && c.amplitude_counts <= bench::kSinCosFullScale,
          fmt::format("SimConfig amplitude_counts (--amplitude) = {}: must be in (0, 32767] ADC counts", c.amplitude_counts));
  require(std::isfinite(c.i_d_cmd) && std::isfinite(c.i_q_cmd), "SimConfig i_d_cmd / i_q_cmd (--id / --iq) must be finite [A]");
  const SensorChainConfig& ch = c.chain;
  require(std::isfinite(ch.sampling_skew.tau),
          "SimConfig chain.sampling_skew.tau (--effect sampling_skew:tau=) must be finite [s]");
  require(std::abs(ch.eccentricity.e) < 1.0 && std::isfinite(ch.eccentricity.phase),
          fmt::format("SimConfig chain.eccentricity.e (--effect eccentricity:e=) = {}: must be in (-1, 1) mechanical rad so "
                      "the resolver angle keeps turning one way; phase must be finite",
                      ch.eccentricity.e));
  require(std::isfinite(ch.mounting_offset.theta_0),
          "SimConfig chain.mounting_offset.theta_0 (--effect mounting_offset:theta_0=) must be finite [rad]");
  require(std::isfinite(ch.current_offsets.off_a) && std::isfinite(ch.current_offsets.off_b),
          "SimConfig chain.current_offsets off_a/off_b (--effect current_offsets:...) must be finite [A]");
  require(ch.current_gain_mismatch.gain_a > -1.0 && ch.current_gain_mismatch.gain_b > -1.0,
          fmt::format("SimConfig chain.current_gain_mismatch gain_a = {}, gain_b = {} (--effect current_gain_mismatch:...): "
                      "relative gain errors must be > -1",
                      ch.current_gain_mismatch.gain_a, ch.current_gain_mismatch.gain_b));
  require(ch.dead_time.t_d >= 0.0 && std::isfinite(ch.dead_time.t_d),
          fmt::format("SimConfig chain.dead_time.t_d (--effect dead_time:t_d=) = {}: must be >= 0 s", ch.dead_time.t_d));
  // Peak measured phase current over a fine theta_e grid: hypot(i_d, i_q) for an
  // ideal chain (amplitude-invariant transform), more with dead time, gains, offsets.
  double i_peak = 0.0;
  for (int i = 0; i < 3600; ++i) {
    const PhaseCurrents m =
        phase_currents_measured(ch, phase_currents_true(ch, c.i_d_cmd, c.i_q_cmd, kTwoPi * i / 3600.0));
    i_peak = std::max({i_peak, std::abs(m.a), std::abs(m.b), std::abs(m.c)});
  }
  i_peak += 5.0 * ch.noise.sigma_i;
  require(i_peak <= kCurrentFullScale,
          fmt::format("SimConfig i_d_cmd/i_q_cmd (--id/--iq): peak phase current {:.3f} A (incl. current-sensor effects, dead "
                      "time and 5 sigma noise) exceeds the PHASE_CURRENTS range +-32.767 A (1 mA/bit, DESIGN 4); lower --iq/--id",
                      i_peak));
  require(c.chain.tracking_loop.omega_n >= 0.0 && std::isfinite(c.chain.tracking_loop.omega_n),
          "SimConfig chain.tracking_loop.omega_n (--effect tracking_loop:omega_n=) must be >= 0 rad/s (0 = ideal converter)");
  require(c.chain.tracking_loop.zeta > 0.0, "SimConfig chain.tracking_loop.zeta (--effect tracking_loop:zeta=) must be > 0");
  require(c.chain.noise.sigma_sc >= 0.0 && c.chain.noise.sigma_i >= 0.0, "SimConfig chain.noise sigma_sc/sigma_i (--effect noise:...) must be >= 0");
  require(std::isfinite(c.theta_m0), "SimConfig theta_m0 must be finite [rad]");
  if (c.alpha_drift_per_s != 0.0) {
    // alpha(t) is linear: checking the end of the run checks every sample.
    const double end = c.chain.amplitude_imbalance.alpha + c.alpha_drift_per_s * SpeedProfile(c.profile).duration();
    require(std::isfinite(c.alpha_drift_per_s) && end > -1.0 && end < 0.2,
            fmt::format("SimConfig alpha_drift_per_s (--alpha-drift) = {}: alpha reaches {} at the end of the run; it "
                        "must stay in (-1, 0.2)",
                        c.alpha_drift_per_s, end));
  }
  // The envelopes must stay inside the ADC: check the peak over a fine theta grid.
  double peak = 0.0;
  for (int i = 0; i < 3600; ++i) {
    const SinCos sc = sensor_envelopes(c.chain, kTwoPi * i / 3600.0);
    peak = std::max({peak, std::abs(sc.s), std::abs(sc.c)});
  }
  const double peak_counts = c.amplitude_counts * peak + 5.0 * c.chain.noise.sigma_sc;
  require(peak_counts <= bench::kSinCosFullScale,
          fmt::format("SimConfig amplitude_counts (--amplitude) = {}: with the chosen effects the sin/cos peak reaches {:.0f} counts "
                      "(incl. 5 sigma noise) > 32767; lower --amplitude",
                      c.amplitude_counts, peak_counts));
  return c;
}

std::int16_t to_i16(double v) {
  return static_cast<std::int16_t>(std::clamp(std::llround(v), -32767LL, 32767LL));
}

}  // namespace

double frames_per_second(const SimConfig& config) {
  return config.sample_rate_hz * (config.reference ? 3.0 : 2.0) + 1e6 / static_cast<double>(kBenchInfoPeriodUs);
}

BenchSimulator::BenchSimulator(SimConfig config)
    : config_(validated(std::move(config))),
      profile_(config_.profile),
      loop_(config_.chain.tracking_loop),
      engine_(config_.seed),
      alpha0_(config_.chain.amplitude_imbalance.alpha) {
  // Samples at t = 0, 1/fs, ... strictly inside the profile's duration.
  const double n = std::ceil(profile_.duration() * config_.sample_rate_hz - 1e-9);
  total_ = static_cast<std::uint64_t>(std::max(n, 1.0));
  // Start the converter converged: at the static angle of the envelopes, at speed.
  const double theta0 = resolver_angle_at(0.0);
  const double phi0 = theta0 - wrap_pi(theta0 - static_rd_angle(sensor_envelopes(config_.chain, theta0)));
  loop_.reset({phi0, config_.p_r * profile_.omega_m(0.0)});
}

double BenchSimulator::sample_time_s(std::uint64_t index) const {
  return static_cast<double>(index) / config_.sample_rate_hz;
}

std::int64_t BenchSimulator::sample_time_us(std::uint64_t index) const {
  return config_.start_time_us + std::llround(static_cast<double>(index) * 1e6 / config_.sample_rate_hz);
}

double BenchSimulator::theta_m_at(double t) const { return config_.theta_m0 + profile_.angle_m(t); }

double BenchSimulator::resolver_angle_at(double t) const {
  return resolver_angle(config_.chain, theta_m_at(t), config_.p_r, config_.p);
}

bool BenchSimulator::next(SimSample& out) {
  if (index_ >= total_) return false;
  const double t = sample_time_s(index_);
  const double p_r = config_.p_r;
  // Drift: alpha is held for each sample period (the loop step below sees the new value).
  if (config_.alpha_drift_per_s != 0.0) config_.chain.amplitude_imbalance.alpha = alpha0_ + config_.alpha_drift_per_s * t;
  if (index_ > 0) {
    const double t_prev = sample_time_s(index_ - 1);
    loop_.advance([&](double tt) { return sensor_envelopes(config_.chain, resolver_angle_at(tt)); }, t_prev,
                  t - t_prev);
  }
  const double theta_m = theta_m_at(t);
  const double theta = p_r * theta_m;
  const double theta_e = config_.p * theta_m;
  const Noise& noise = config_.chain.noise;
  SimSample s{};
  s.t_us = sample_time_us(index_);
  s.index = index_;
  s.counter = static_cast<std::uint8_t>(index_ & 0xFFU);
  s.theta_m = wrap_2pi(theta_m);
  s.theta = wrap_2pi(theta);
  s.theta_e = wrap_2pi(theta_e);
  s.omega_m = profile_.omega_m(t);
  // Fixed draw order (sin, cos, i_a, i_b, i_c) keeps a seed's output stable.
  const double theta_seen = resolver_angle_at(t);
  const double theta_seen_cos =
      config_.chain.sampling_skew.active() ? resolver_angle_at(t + config_.chain.sampling_skew.tau) : theta_seen;
  const SinCos sc = sampled_envelopes(config_.chain, theta_seen, theta_seen_cos);
  s.sin_counts = to_i16(config_.amplitude_counts * sc.s + gaussian_noise(engine_, noise.sigma_sc));
  s.cos_counts = to_i16(config_.amplitude_counts * sc.c + gaussian_noise(engine_, noise.sigma_sc));
  s.rd_counts = quantize_rd_angle(loop_.state().phi, config_.rd_bits);
  s.rd_angle = rd_counts_to_angle(s.rd_counts);
  const PhaseCurrents i =
      phase_currents_measured(config_.chain, phase_currents_true(config_.chain, config_.i_d_cmd, config_.i_q_cmd, theta_e));
  const double ma_per_amp = 1.0 / bench::kCurrentAmpsPerBit;
  s.i_a_ma = to_i16((i.a + gaussian_noise(engine_, noise.sigma_i)) * ma_per_amp);
  s.i_b_ma = to_i16((i.b + gaussian_noise(engine_, noise.sigma_i)) * ma_per_amp);
  s.i_c_ma = to_i16((i.c + gaussian_noise(engine_, noise.sigma_i)) * ma_per_amp);
  // Rounding can give exactly 2^32 just below 2pi: that is angle 0 again.
  const auto ref = static_cast<std::uint64_t>(std::llround(s.theta_m / kTwoPi * bench::kRefAngleCounts));
  s.ref_counts = static_cast<std::uint32_t>(ref & 0xFFFFFFFFULL);
  out = s;
  ++index_;
  return true;
}

void BenchSimulator::append_frames(const SimSample& s, std::vector<CanFrame>& out) const {
  const auto with_iface = [&](CanFrame f) {
    f.set_iface(config_.iface);
    out.push_back(f);
  };
  std::int64_t t = s.t_us;
  with_iface(bench::encode_resolver_sample(t++, s.counter, s.sin_counts, s.cos_counts, s.rd_counts));
  with_iface(bench::encode_phase_currents(t++, s.counter, s.i_a_ma, s.i_b_ma, s.i_c_ma));
  if (config_.reference) with_iface(bench::encode_reference_angle(t++, s.counter, s.ref_counts));
  const std::int64_t rel = s.t_us - config_.start_time_us;
  const bool info_due =
      s.index == 0 || rel / kBenchInfoPeriodUs != (sample_time_us(s.index - 1) - config_.start_time_us) / kBenchInfoPeriodUs;
  if (info_due) {
    with_iface(bench::encode_bench_info(t, static_cast<std::uint8_t>(config_.p_r), static_cast<std::uint8_t>(config_.p),
                                        static_cast<std::uint8_t>(config_.rd_bits),
                                        static_cast<std::uint16_t>(config_.sample_rate_hz)));
  }
}

}  // namespace resolver
