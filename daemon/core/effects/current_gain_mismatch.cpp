#include "daemon/core/effects/current_gain_mismatch.h"

#include <cmath>
#include <numbers>

namespace resolver {

PhaseCurrents apply_current_gain_mismatch(const CurrentGainMismatch& p, const PhaseCurrents& in) {
  return {(1.0 + p.gain_a) * in.a, (1.0 + p.gain_b) * in.b, in.c};
}

DqCurrents current_gain_mismatch_dq_error(const CurrentGainMismatch& p, double i_d, double i_q, double theta_e) {
  // The Clarke error of the extra a and b parts, then Park (DESIGN 3).
  const PhaseCurrents i = ideal_phase_currents(i_d, i_q, theta_e);
  const double d_alpha = p.gain_a * i.a;
  const double d_beta = p.gain_b * i.b / std::numbers::sqrt3;
  const double ce = std::cos(theta_e);
  const double se = std::sin(theta_e);
  return {d_alpha * ce + d_beta * se, -d_alpha * se + d_beta * ce};
}

double current_gain_mismatch_ripple_2x(const CurrentGainMismatch& p, double i_d, double i_q) {
  const double u = p.gain_a - 0.5 * p.gain_b;
  return 0.5 * std::hypot(i_d, i_q) * std::sqrt(u * u + p.gain_b * p.gain_b / 12.0);
}

PhaseCurrents compensate_current_gain_mismatch(const CurrentGainMismatch& p, const PhaseCurrents& measured) {
  return {measured.a / (1.0 + p.gain_a), measured.b / (1.0 + p.gain_b), measured.c};
}

}  // namespace resolver
