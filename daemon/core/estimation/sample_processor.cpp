#include "daemon/core/estimation/sample_processor.h"

#include <cmath>
#include <limits>

#include "daemon/core/estimation/dq_transform.h"

namespace resolver {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

SampleProcessor::SampleProcessor(const ProcessorConfig& config)
    : config_(config),
      estimator_(config.hwang),
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

  out.revolution = estimator_.update(in.t, theta_meas);
  if (out.revolution && config_.compensate && estimator_.converged()) active_alpha_ = estimator_.alpha();

  const double p_r = config_.p_r;
  out.speed_mech = speed_.update(in.t, theta_meas) / p_r;
  // Compensation in the angle domain (Hwang Fig. 5, DESIGN 3 sign): theta_c = theta_rd + eps_hat.
  out.eps_hat = amplitude_imbalance_eps(active_alpha_, theta_meas);
  out.theta_comp = wrap_2pi(theta_meas + out.eps_hat);

  double theta_ref_cont = kNaN;
  if (in.has_ref) {
    theta_ref_cont = ref_unwrap_.update(in.theta_m_ref);
    out.theta_ref = wrap_2pi(p_r * in.theta_m_ref);
    out.eps_ref = wrap_pi(out.theta_ref - theta_meas);
  } else {
    out.theta_ref = kNaN;
    out.eps_ref = kNaN;
  }

  const double rd_cont = rd_unwrap_.update(theta_meas);
  if (!in.has_currents) return out;
  out.has_dq = true;
  const double ratio = static_cast<double>(config_.p) / p_r;  // theta_e = (p/p_r) theta (Hwang eq. 19)
  out.electrical_freq_hz = config_.p * out.speed_mech / kTwoPi;
  const ClarkeTransform ab(in.i_a, in.i_b, in.i_c);

  const double e_raw = ratio * rd_cont;
  const ParkTransform raw(ab.alpha, ab.beta, e_raw);
  out.i_d_raw = raw.d;
  out.i_q_raw = raw.q;
  const double e_comp = ratio * (rd_cont + out.eps_hat);
  const ParkTransform comp(ab.alpha, ab.beta, e_comp);
  out.i_d_comp = comp.d;
  out.i_q_comp = comp.q;

  if (ripple_raw_.update(e_raw, raw.d, raw.q)) {
    ripple_.raw = ripple_raw_.last();
    ripple_.raw_valid = true;
    out.ripple_raw_updated = true;
  }
  if (ripple_comp_.update(e_comp, comp.d, comp.q)) {
    ripple_.comp = ripple_comp_.last();
    ripple_.comp_valid = true;
    out.ripple_comp_updated = true;
  }
  if (in.has_ref) {
    const double e_ref = config_.p * theta_ref_cont;
    const ParkTransform ref(ab.alpha, ab.beta, e_ref);
    out.i_d_ref = ref.d;
    out.i_q_ref = ref.q;
    if (ripple_ref_.update(e_ref, ref.d, ref.q)) {
      ripple_.ref = ripple_ref_.last();
      ripple_.ref_valid = true;
      out.ripple_ref_updated = true;
    }
  } else {
    out.i_d_ref = kNaN;
    out.i_q_ref = kNaN;
  }
  return out;
}

}  // namespace resolver
