#include "daemon/core/effects/mounting_offset.h"

#include <cmath>

#include "daemon/core/angles.h"

namespace resolver {

double mounting_offset_resolver_shift(const MountingOffset& m, int p_r, int p) {
  return m.theta_0 * static_cast<double>(p_r) / static_cast<double>(p);
}

DqCurrents mounting_offset_rotor_currents(const MountingOffset& m, double i_d_cmd, double i_q_cmd) {
  const double c = std::cos(m.theta_0);
  const double s = std::sin(m.theta_0);
  return {i_d_cmd * c - i_q_cmd * s, i_d_cmd * s + i_q_cmd * c};
}

double mounting_offset_error(const MountingOffset& m, int p_r, int p) {
  return -mounting_offset_resolver_shift(m, p_r, p);
}

double estimate_mounting_offset(double i_d_ref, double i_q_ref, double i_d_cmd, double i_q_cmd) {
  if ((i_d_ref == 0.0 && i_q_ref == 0.0) || (i_d_cmd == 0.0 && i_q_cmd == 0.0)) return 0.0;
  // The rotor-frame vector is the command rotated by +theta_0.
  return wrap_pi(std::atan2(i_q_ref, i_d_ref) - std::atan2(i_q_cmd, i_d_cmd));
}

double compensate_mounting_offset(const MountingOffset& m, double theta_e_drive) {
  return theta_e_drive - m.theta_0;
}

}  // namespace resolver
