#include "daemon/core/model/compensator.h"

#include <cmath>

namespace resolver {

Compensator::Compensator(Model model) : model_(std::move(model)), active_(model_.has_angle_terms()) {}

void Compensator::replace_model(Model model) {
  model_ = std::move(model);
  active_ = model_.has_angle_terms();
}

double Compensator::correct(double theta_meas, double t, double omega, double accel, bool sincos) {
  if (!active_) {
    last_eps_ = 0.0;
    return wrap_2pi(theta_meas);
  }
  if (omega > 0.0) direction_ = 1.0;
  if (omega < 0.0) direction_ = -1.0;
  const double cont = unwrap_.update(wrap_2pi(theta_meas));
  SignatureRow row;
  row.t = t;
  row.omega = omega;
  row.accel = accel;
  row.direction = direction_;
  row.p_r = model_.p_r();
  row.p = model_.p();
  double eps = last_eps_;
  for (int i = 0; i < kIterations; ++i) {
    row.theta = cont + eps;
    row.theta_m = row.theta / model_.p_r() + cycle_offset_;
    const SignalValues pred = model_.predict(row);
    eps = sincos ? pred.sa : pred.rd;
  }
  last_eps_ = eps;
  last_theta_c_cont_ = cont + eps;
  return wrap_2pi(cont + eps);
}

void Compensator::learn_reference(double theta_m_ref) {
  // Which of the p_r electrical cycles the resolver is in: the reference's
  // mechanical angle against the compensated angle / p_r, wrapped to one cycle.
  const double offset = wrap_pi(theta_m_ref - last_theta_c_cont_ / model_.p_r());
  if (!cycle_known_) {
    cycle_offset_ = offset;
    cycle_known_ = true;
    return;
  }
  // Follow slowly (the reference's own noise); a whole-cycle jump is taken at once.
  const double d = wrap_pi(offset - cycle_offset_);
  cycle_offset_ += std::abs(d) > 0.1 ? d : 0.01 * d;
}

}  // namespace resolver
