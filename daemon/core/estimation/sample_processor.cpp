#include "daemon/core/estimation/sample_processor.h"

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>

#include "daemon/core/estimation/dq_transform.h"
#include "daemon/core/estimation/estimator_models.h"

namespace resolver {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A value no registry effect has: the sin/cos signal's amplitude (a nuisance of its fit).
ModelParameter extra_param(std::string name, double value, double std_error, std::string unit) {
  return ModelParameter{.name = std::move(name), .value = value, .std_error = std_error, .unit = std::move(unit)};
}

/// Every method, the default first: what the config accepts and what messages list.
constexpr std::array kEstimatorMethods{EstimatorMethod::kModel, EstimatorMethod::kHwangIntegral,
                                       EstimatorMethod::kSinCosLeastSquares, EstimatorMethod::kFourierReference};
}  // namespace

std::optional<EstimatorMethod> estimator_from_name(std::string_view name) {
  for (const EstimatorMethod m : kEstimatorMethods) {
    if (estimator_name(m) == name) return m;
  }
  return std::nullopt;
}

std::string estimator_names() {
  std::string out;
  for (const EstimatorMethod m : kEstimatorMethods) {
    if (!out.empty()) out += ", ";
    out += estimator_name(m);
  }
  return out;
}

std::string_view estimator_name(EstimatorMethod method) {
  switch (method) {
    case EstimatorMethod::kModel: return "model";
    case EstimatorMethod::kHwangIntegral: return "hwang_integral";
    case EstimatorMethod::kSinCosLeastSquares: return "sincos_least_squares";
    case EstimatorMethod::kFourierReference: return "fourier_reference";
  }
  return "unknown";
}

SampleProcessor::SampleProcessor(const ProcessorConfig& config)
    : config_(config),
      estimator_(config.hwang),
      sincos_ls_(config.sincos),
      fourier_(config.fourier),
      ripple_raw_(config.ripple_revolutions),
      ripple_comp_(config.ripple_revolutions),
      ripple_ref_(config.ripple_revolutions) {}

void SampleProcessor::set_pole_pairs(int p_r, int p) {
  if (p_r == config_.p_r && p == config_.p) return;
  config_.p_r = p_r;
  config_.p = p;
  *this = SampleProcessor(config_);
}

SampleOutput SampleProcessor::process(const SampleInput& in) {
  SampleOutput out;
  out.theta_sincos = in.has_sincos ? wrap_2pi(std::atan2(in.sin, in.cos)) : kNaN;
  // Without an R/D angle, the angle from the raw sin/cos stands in for it.
  const bool has_angle = in.has_rd || in.has_sincos;
  if (!has_angle) return out;
  out.has_angle = true;
  const double theta_meas = in.has_rd ? wrap_2pi(in.theta_rd) : out.theta_sincos;
  out.theta_rd = theta_meas;
  rd_unwrap_.update(theta_meas);
  ++samples_;
  feed_estimator(in, theta_meas, out);
  count_revolution(out);
  out.moving = update_motion_gate();
  const double omega = speed_.update(in.t, theta_meas);
  out.speed_mech = omega / config_.p_r;
  compensate(in, theta_meas, omega, out);
  reference_angles(in, theta_meas, out);
  if (in.has_currents) dq_and_ripple(in, out);
  return out;
}

void SampleProcessor::feed_estimator(const SampleInput& in, double theta_meas, SampleOutput& out) {
  const double p_r = config_.p_r;
  // Hwang's integral runs beside every method (the seed's baseline the reports show
  // next to the default).
  if (config_.method != EstimatorMethod::kHwangIntegral) out.revolution = estimator_.update(in.t, theta_meas);
  switch (config_.method) {
    case EstimatorMethod::kModel:
      if (model_updated_) {
        model_updated_ = false;
        out.estimate_updated = true;
      }
      break;
    case EstimatorMethod::kHwangIntegral:
      out.revolution = estimator_.update(in.t, theta_meas);
      if (out.revolution) {
        out.estimate_updated = true;
        if (estimator_.converged()) adopt(estimated_model());
      }
      break;
    case EstimatorMethod::kSinCosLeastSquares:
      if (in.has_sincos) {
        if (in.has_ref) {
          sincos_ls_.add(in.sin, in.cos, p_r * in.theta_m_ref);
        } else {
          sincos_ls_.add(in.sin, in.cos);
        }
      }
      break;
    case EstimatorMethod::kFourierReference:
      if (in.has_ref) fourier_.add(p_r * in.theta_m_ref, theta_meas);
      break;
  }
}

void SampleProcessor::count_revolution(SampleOutput& out) {
  // The other estimators solve once per resolver electrical revolution: a
  // revolution is 2pi of travel from the last one's end (noise jittering across
  // a level at a standstill is not one).
  if (!rev_started_) {
    rev_started_ = true;
    rev_anchor_ = rd_unwrap_.continuous;
  } else if (std::abs(rd_unwrap_.continuous - rev_anchor_) >= kTwoPi) {
    rev_anchor_ += rd_unwrap_.continuous > rev_anchor_ ? kTwoPi : -kTwoPi;
    ++revolutions_;
    close_revolution(out);
  }
}

bool SampleProcessor::update_motion_gate() {
  // Travel over the last kTravelSpan samples against the noise of the angle's second
  // differences (sigma = 1.2533 mean|d2| / sqrt 6 for Gaussian noise).
  const double cont = rd_unwrap_.continuous;
  const std::size_t cap = kTravelSpan + 1;
  if (recent_n_ >= 2) {
    const double a = recent_[(recent_n_ - 1) % cap], b = recent_[(recent_n_ - 2) % cap];
    const double d2 = std::abs(cont - 2.0 * a + b);
    second_diff_ema_ += (d2 - second_diff_ema_) * (recent_n_ < 64 ? 1.0 / static_cast<double>(recent_n_) : 1.0 / 64.0);
  }
  recent_[recent_n_ % cap] = cont;
  ++recent_n_;
  if (recent_n_ > kTravelSpan) {
    const double travel = std::abs(cont - recent_[(recent_n_ - 1 - kTravelSpan) % cap]);
    const double sigma = std::max(1.2533 * second_diff_ema_ / std::sqrt(6.0), 1e-9);
    if (moving_ && travel < 3.0 * sigma) moving_ = false;
    else if (!moving_ && travel > 6.0 * sigma) moving_ = true;
  }
  return moving_;
}

void SampleProcessor::compensate(const SampleInput& in, double theta_meas, double omega, SampleOutput& out) {
  // Compensation (docs/ARCHITECTURE.md §3 sign): theta_c = theta_rd + eps_hat, one
  // path for every method: the exported table, else the Model inverted.
  if (table_ && config_.compensate) {
    out.theta_comp = table_->correct(theta_meas, omega, in.has_ref ? wrap_2pi(in.theta_m_ref) : kNaN);
    out.eps_hat = wrap_pi(out.theta_comp - theta_meas);
  } else if (config_.compensate && model_set_) {
    // Signal domain: the angle of the raw envelopes with the envelope prediction
    // (bypasses the R/D converter); angle domain: the R/D angle with the rd one.
    const bool signal = config_.domain == CompensationDomain::kSignal && in.has_sincos;
    out.theta_comp = compensator_.correct(signal ? out.theta_sincos : theta_meas, in.t, omega, 0.0, signal);
    out.eps_hat = wrap_pi(out.theta_comp - theta_meas);
    if (in.has_ref) compensator_.learn_reference(wrap_2pi(in.theta_m_ref));
  } else {
    out.eps_hat = 0.0;
    out.theta_comp = theta_meas;
  }
}

void SampleProcessor::reference_angles(const SampleInput& in, double theta_meas, SampleOutput& out) {
  if (in.has_ref) {
    ref_cont_ = ref_unwrap_.update(in.theta_m_ref);
    out.theta_ref = wrap_2pi(config_.p_r * in.theta_m_ref);
    out.eps_ref = wrap_pi(out.theta_ref - theta_meas);
  } else {
    ref_cont_ = kNaN;
    out.theta_ref = kNaN;
    out.eps_ref = kNaN;
  }
}

void SampleProcessor::dq_and_ripple(const SampleInput& in, SampleOutput& out) {
  const double rd_cont = rd_unwrap_.continuous;
  out.has_dq = true;
  const double ratio = static_cast<double>(config_.p) / config_.p_r;  // theta_e = (p/p_r) theta (Hwang eq. 19)
  out.electrical_freq_hz = config_.p * out.speed_mech / kTwoPi;
  const ClarkeTransform ab(in.i_a, in.i_b, in.i_c);

  // The ripple's currents: the measured ones or, on a sample the gate finds a spike
  // (current_spike_gate.h), its line's estimate turned back to alpha/beta with the raw
  // angle: a sample left out of a revolution's DFT would leak the 2x ripple into every
  // order (~10 mA per missing sample of 0.65 A at 2x, N = 130). The sample's published dq
  // stay the measured ones.
  const double theta_raw = ratio * rd_cont;
  const double c_raw = std::cos(theta_raw), s_raw = std::sin(theta_raw);
  const ParkTransform raw(ab.alpha, ab.beta, c_raw, s_raw);
  double alpha = ab.alpha, beta = ab.beta;
  if (!spike_gate_.pass(in.t, raw.d, raw.q)) {
    const CurrentSpikeGate::Estimate e = spike_gate_.line();
    alpha = e.d * c_raw - e.q * s_raw;
    beta = e.d * s_raw + e.q * c_raw;
  }
  // dq and ripple with one angle: cos/sin of theta_e computed once, shared by
  // the Park transform and the ripple DFT.
  auto dq_with = [&](double theta_e, double c, double s, RevolutionRipple& tracker, RippleAmplitudes& ripple,
                     bool& valid, double& i_d, double& i_q) {
    const ParkTransform dq(ab.alpha, ab.beta, c, s);
    i_d = dq.d;
    i_q = dq.q;
    const ParkTransform fed(alpha, beta, c, s);
    if (!tracker.update(theta_e, c, s, fed.d, fed.q)) return false;
    ripple = tracker.last();
    valid = true;
    return true;
  };
  out.ripple_raw_updated =
      dq_with(theta_raw, c_raw, s_raw, ripple_raw_, ripple_.raw, ripple_.raw_valid, out.i_d_raw, out.i_q_raw);
  const double theta_comp = ratio * (rd_cont + out.eps_hat);
  out.ripple_comp_updated = dq_with(theta_comp, std::cos(theta_comp), std::sin(theta_comp), ripple_comp_, ripple_.comp,
                                    ripple_.comp_valid, out.i_d_comp, out.i_q_comp);
  if (in.has_ref) {
    const double theta_ref = config_.p * ref_cont_;
    out.ripple_ref_updated = dq_with(theta_ref, std::cos(theta_ref), std::sin(theta_ref), ripple_ref_, ripple_.ref,
                                     ripple_.ref_valid, out.i_d_ref, out.i_q_ref);
  } else {
    out.i_d_ref = kNaN;
    out.i_q_ref = kNaN;
  }
}

void SampleProcessor::set_model(Model model, std::int64_t samples, double revolutions) {
  adopt(std::move(model));
  if (config_.method != EstimatorMethod::kModel) return;
  model_updated_ = true;
  model_samples_ = samples;
  model_revolutions_ = revolutions;
}

void SampleProcessor::adopt(Model model) {
  if (!model_set_) compensator_ = Compensator(std::move(model));
  else compensator_.replace_model(std::move(model));
  model_set_ = true;
}

void SampleProcessor::close_revolution(SampleOutput& out) {
  if (config_.method == EstimatorMethod::kSinCosLeastSquares) {
    sincos_fit_ = sincos_ls_.solve();
  } else if (config_.method == EstimatorMethod::kFourierReference) {
    fourier_fit_ = fourier_.solve();
  } else {
    return;
  }
  out.estimate_updated = true;
  Model own = estimated_model();
  if (!own.empty()) adopt(std::move(own));
}

Model SampleProcessor::estimated_model() const {
  switch (config_.method) {
    case EstimatorMethod::kModel: return model_set_ ? compensator_.model() : Model{};
    case EstimatorMethod::kHwangIntegral:
      return hwang_model(estimator_.alpha(), estimator_.alpha_stderr(), config_.p_r, config_.p);
    case EstimatorMethod::kSinCosLeastSquares:
      return sincos_fit_ ? sincos_model(*sincos_fit_, config_.p_r, config_.p) : Model{};
    case EstimatorMethod::kFourierReference:
      return fourier_fit_ ? fourier_model(*fourier_fit_, config_.p_r, config_.p) : Model{};
  }
  return {};
}

bool SampleProcessor::compensating() const {
  if (!config_.compensate) return false;
  if (table_) return true;
  return model_set_ && compensator_.active();
}

ModelEstimate SampleProcessor::estimate() const {
  ModelEstimate e;
  e.method = std::string(estimator_name(config_.method));
  e.samples = samples_;
  e.revolutions = static_cast<double>(revolutions_);
  e.params = estimated_model().parameters();
  switch (config_.method) {
    case EstimatorMethod::kModel:
      e.samples = model_samples_;
      e.revolutions = model_revolutions_;
      e.converged = model_set_;
      break;
    case EstimatorMethod::kHwangIntegral:
      e.samples = estimator_.samples_used();
      e.revolutions = static_cast<double>(estimator_.revolutions());
      e.converged = estimator_.converged();
      break;
    case EstimatorMethod::kSinCosLeastSquares:
      if (sincos_fit_) {
        const SinCosFit& f = *sincos_fit_;
        e.params.push_back(extra_param("signal.amplitude", f.amplitude.value, f.amplitude.std_error, "[signal units]"));
        e.samples = f.samples_seen;
        e.converged = revolutions_ >= 1;
      }
      break;
    case EstimatorMethod::kFourierReference:
      if (fourier_fit_) {
        e.samples = static_cast<std::int64_t>(fourier_fit_->samples);
        e.converged = revolutions_ >= 1;
      }
      break;
  }
  return e;
}

}  // namespace resolver
