#include "tools/sim/bench_simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/angles.h"
#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/phase_currents.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/decode/bench_layout.h"

namespace resolver {

ChainValues default_sim_chain() {
  ChainValues chain;
  chain.set("tracking_loop", "omega_n", 3000.0);  // [rad/s] see the header
  chain.set("tracking_loop", "zeta", 0.7);
  chain.set("noise", "sigma_sc", 2.0);  // [counts]
  chain.set("noise", "sigma_i", 0.02);  // [A]
  return chain;
}

namespace {

constexpr std::int64_t kBenchInfoPeriodUs = 100000;  // 10 Hz (docs/ARCHITECTURE.md section 4)
constexpr double kCurrentFullScale = 32767.0 * bench::kCurrentAmpsPerBit;  // [A] i16 at 1 mA/bit

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

/// rd_bits' range and default: the quantization effect's list (quantization.h), the one place they are written.
constexpr const ParamInfo& kRdBits = QuantizationParams::info("rd_bits");

/// Makes rd_bits and the chain's quantization.rd_bits one value (see SimConfig::rd_bits).
void reconcile_rd_bits(SimConfig& c) {
  const int from_chain = static_cast<int>(c.chain.get("quantization", "rd_bits"));
  const int dflt = static_cast<int>(kRdBits.neutral);
  if (from_chain != dflt && c.rd_bits != dflt && from_chain != c.rd_bits) {
    throw std::invalid_argument(fmt::format(
        "SimConfig: rd_bits = {} but chain quantization.rd_bits = {}; they are the same R/D resolution, set one "
        "(--rd-bits or --effect quantization:rd_bits=N)",
        c.rd_bits, from_chain));
  }
  const int bits = from_chain != dflt ? from_chain : c.rd_bits;
  c.rd_bits = bits;
  if (bits >= kRdBits.min && bits <= kRdBits.max) c.chain.set("quantization", "rd_bits", bits);
}

SimConfig validated(SimConfig c) {
  require(c.p_r >= 1 && c.p_r <= 255, fmt::format("SimConfig p_r (--p-r) = {}: resolver pole pairs must be 1..255 (u8 in BENCH_INFO)", c.p_r));
  require(c.p >= 1 && c.p <= 255, fmt::format("SimConfig p (--p) = {}: motor pole pairs must be 1..255 (u8 in BENCH_INFO)", c.p));
  reconcile_rd_bits(c);
  require(c.rd_bits >= kRdBits.min && c.rd_bits <= kRdBits.max,
          fmt::format("SimConfig rd_bits (--rd-bits) = {}: R/D resolution must be {}..{} bits (u16 rd_angle field)",
                      c.rd_bits, kRdBits.min, kRdBits.max));
  require(c.sample_rate_hz >= 1.0 && c.sample_rate_hz <= 65535.0 && c.sample_rate_hz == std::round(c.sample_rate_hz),
          fmt::format("SimConfig sample_rate_hz (--sample-rate) = {}: must be a whole number of Hz in 1..65535 (u16 in BENCH_INFO)",
                      c.sample_rate_hz));
  require(c.amplitude_counts > 0.0 && c.amplitude_counts <= bench::kSinCosFullScale,
          fmt::format("SimConfig amplitude_counts (--amplitude) = {}: must be in (0, 32767] ADC counts", c.amplitude_counts));
  require(std::isfinite(c.i_d_cmd) && std::isfinite(c.i_q_cmd), "SimConfig i_d_cmd / i_q_cmd (--id / --iq) must be finite [A]");
  // Every active effect's own checks (registry: Effect::validate) and ranges (ChainValues::set).
  c.chain.validate();
  const ForwardChain chain(c.chain, c.p_r, c.p);
  // Peak measured phase current over a fine theta_e grid: hypot(i_d, i_q) for an
  // ideal chain (amplitude-invariant transform), more with dead time, gains, offsets.
  double i_peak = 0.0;
  for (int i = 0; i < 3600; ++i) {
    const double theta_e = kTwoPi * i / 3600.0;
    const PhaseCurrents m = chain.measured_currents(chain.machine_currents(c.i_d_cmd, c.i_q_cmd, theta_e), theta_e);
    i_peak = std::max({i_peak, std::abs(m.a), std::abs(m.b), std::abs(m.c)});
  }
  i_peak += 5.0 * chain.impairments().sigma_i;
  require(i_peak <= kCurrentFullScale,
          fmt::format("SimConfig i_d_cmd/i_q_cmd (--id/--iq): peak phase current {:.3f} A (incl. current-sensor effects, dead "
                      "time and 5 sigma noise) exceeds the PHASE_CURRENTS range +-32.767 A (1 mA/bit, docs/ARCHITECTURE.md section 4); lower --iq/--id",
                      i_peak));
  require(std::isfinite(c.theta_m0), "SimConfig theta_m0 must be finite [rad]");
  if (c.alpha_drift_per_s != 0.0) {
    // alpha(t) is linear: checking the end of the run checks every sample.
    const double end = c.chain.get("amplitude_imbalance", "alpha") + c.alpha_drift_per_s * SpeedProfile(c.profile).duration();
    require(std::isfinite(c.alpha_drift_per_s) && end > -1.0 && end < 0.2,
            fmt::format("SimConfig alpha_drift_per_s (--alpha-drift) = {}: alpha reaches {} at the end of the run; it "
                        "must stay in (-1, 0.2)",
                        c.alpha_drift_per_s, end));
  }
  // The envelopes must stay inside the ADC: check the peak over a fine theta grid, at
  // times through the run (an effect may change them in time: envelope_drift). A
  // drift is monotone over the run, so its ends and kTimeSteps between check it.
  // They must also keep encoding the angle: against the start, no envelope pair may
  // turn by 90 degrees or more (a gain 1 + g t through zero reverses them).
  constexpr int kTimeSteps = 16;
  const double duration = SpeedProfile(c.profile).duration();
  double peak = 0.0;
  for (int k = 0; k <= kTimeSteps; ++k) {
    const double t = duration * k / kTimeSteps;
    for (int i = 0; i < 3600; ++i) {
      const double theta = kTwoPi * i / 3600.0;
      const SinCos sc = chain.envelopes(theta, t);
      peak = std::max({peak, std::abs(sc.s), std::abs(sc.c)});
      if (k == 0) continue;
      const SinCos start = chain.envelopes(theta, 0.0);
      require(sc.s * start.s + sc.c * start.c > 0.0 || (start.s == 0.0 && start.c == 0.0),
              fmt::format("SimConfig profile ({} s): with the chosen effects the sin/cos envelopes at t = {:.3g} s are "
                          "reversed against those at the start (a drifting gain reaches 0); shorten the run or lower "
                          "the drift",
                          duration, t));
    }
  }
  const double peak_counts = c.amplitude_counts * peak + 5.0 * chain.impairments().sigma_sc;
  require(peak_counts <= bench::kSinCosFullScale,
          fmt::format("SimConfig amplitude_counts (--amplitude) = {}: with the chosen effects the sin/cos peak reaches {:.0f} counts "
                      "(incl. 5 sigma noise, over the whole run) > 32767; lower --amplitude",
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
      chain_(config_.chain, config_.p_r, config_.p),
      loop_(chain_.converter().loop),
      engine_(config_.seed),
      alpha0_(config_.chain.get("amplitude_imbalance", "alpha")) {
  // Samples at t = 0, 1/fs, ... strictly inside the profile's duration.
  const double n = std::ceil(profile_.duration() * config_.sample_rate_hz - 1e-9);
  total_ = static_cast<std::uint64_t>(std::max(n, 1.0));
  // Start the converter converged: at the static angle of the envelopes, at speed.
  const double theta0 = seen_angle(0.0, false);
  const double phi0 = theta0 - wrap_pi(theta0 - static_rd_angle(converter_envelopes(0.0)));
  loop_.reset({phi0, config_.p_r * profile_.omega_m(0.0)});
}

double BenchSimulator::sample_time_s(std::uint64_t index) const {
  return static_cast<double>(index) / config_.sample_rate_hz;
}

std::int64_t BenchSimulator::sample_time_us(std::uint64_t index) const {
  return config_.start_time_us + std::llround(static_cast<double>(index) * 1e6 / config_.sample_rate_hz);
}

double BenchSimulator::theta_m_at(double t) const { return config_.theta_m0 + profile_.angle_m(t); }

double BenchSimulator::seen_angle(double t, bool commit) {
  const double tr = t - chain_.time_shift();
  return chain_.resolver_angle(theta_m_at(tr), profile_.omega_m(tr), commit);
}

SinCos BenchSimulator::converter_envelopes(double t) {
  const SinCos at_sin = chain_.envelopes(seen_angle(t, false), t);
  const double cos_dt = chain_.timing().converter_cos_dt;
  if (cos_dt == 0.0) return at_sin;
  return {at_sin.s, chain_.envelopes(seen_angle(t + cos_dt, false), t + cos_dt).c};
}

bool BenchSimulator::next(SimSample& out) {
  if (index_ >= total_) return false;
  const double t = sample_time_s(index_);
  const double p_r = config_.p_r;
  // Drift: alpha is held for each sample period (the loop step below sees the new value).
  if (config_.alpha_drift_per_s != 0.0) {
    chain_.set_value(amplitude_imbalance_effect(), 0, alpha0_ + config_.alpha_drift_per_s * t);
  }
  if (index_ > 0) {
    const double t_prev = sample_time_s(index_ - 1);
    loop_.advance([&](double tt) { return converter_envelopes(tt); }, t_prev, t - t_prev);
  }
  const double theta_m = theta_m_at(t);
  const double theta = p_r * theta_m;
  const double theta_e = config_.p * theta_m;
  const Impairments& imp = chain_.impairments();
  SimSample s{};
  s.t_us = sample_time_us(index_);
  s.index = index_;
  s.counter = static_cast<std::uint8_t>(index_ & 0xFFU);
  s.theta_m = wrap_2pi(theta_m);
  s.theta = wrap_2pi(theta);
  s.theta_e = wrap_2pi(theta_e);
  s.omega_m = profile_.omega_m(t);
  // Fixed draw order (sin, cos, i_a, i_b, i_c, then outliers) keeps a seed's output stable.
  const double theta_seen = seen_angle(t, true);  // the sample instant: motion states advance here
  const double dsp_cos_dt = chain_.timing().dsp_cos_dt;
  const double theta_seen_cos = dsp_cos_dt != 0.0 ? seen_angle(t + dsp_cos_dt, false) : theta_seen;
  const SinCos sc{chain_.envelopes(theta_seen, t).s, chain_.envelopes(theta_seen_cos, t + dsp_cos_dt).c};
  double sin_counts = config_.amplitude_counts * sc.s + gaussian_noise(engine_, imp.sigma_sc);
  const double cos_counts = config_.amplitude_counts * sc.c + gaussian_noise(engine_, imp.sigma_sc);
  s.rd_counts = quantize_rd_angle(loop_.state().phi, config_.rd_bits);
  s.rd_angle = rd_counts_to_angle(s.rd_counts);
  const PhaseCurrents i = chain_.measured_currents(chain_.machine_currents(config_.i_d_cmd, config_.i_q_cmd, theta_e), theta_e);
  const double ma_per_amp = 1.0 / bench::kCurrentAmpsPerBit;
  s.i_a_ma = to_i16((i.a + gaussian_noise(engine_, imp.sigma_i)) * ma_per_amp);
  s.i_b_ma = to_i16((i.b + gaussian_noise(engine_, imp.sigma_i)) * ma_per_amp);
  s.i_c_ma = to_i16((i.c + gaussian_noise(engine_, imp.sigma_i)) * ma_per_amp);
  if (imp.outlier_rate > 0.0) {
    // An impulsive sample with probability rate / sample rate (Bernoulli per sample).
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    if (uniform(engine_) < imp.outlier_rate / config_.sample_rate_hz) {
      sin_counts += uniform(engine_) < 0.5 ? -imp.outlier_size : imp.outlier_size;
    }
  }
  if (imp.current_outlier_rate > 0.0) {
    // Drawn after everything above, and only with the effect on: a seed's log without it is
    // unchanged. The spike is added to the sample as the ADC read it (saturating at int16).
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    if (uniform(engine_) < imp.current_outlier_rate / config_.sample_rate_hz) {
      const double spike = uniform(engine_) < imp.current_outlier_positive ? imp.current_outlier_size
                                                                           : -imp.current_outlier_size;
      s.i_a_ma = to_i16(s.i_a_ma + spike * ma_per_amp);
    }
  }
  s.sin_counts = to_i16(sin_counts);
  s.cos_counts = to_i16(cos_counts);
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
