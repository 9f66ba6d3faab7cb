#include "daemon/core/effects/dead_time.h"

#include <cmath>
#include <numbers>

#include "daemon/core/angles.h"

namespace resolver {

namespace {
/// The distortion of one phase whose fundamental has phase psi [rad] and peak magnitude [A].
double phase_distortion(double k, double magnitude, double psi) {
  return k * magnitude * (std::sin(7.0 * psi) - std::sin(5.0 * psi));
}
}  // namespace

PhaseCurrents apply_dead_time(const DeadTime& p, const PhaseCurrents& fundamental) {
  if (!p.active()) return fundamental;
  // Clarke (DESIGN 3) gives the fundamental's vector |I| e^{j psi}; phase x has psi_x = psi - x 2pi/3.
  const double alpha = fundamental.a;
  const double beta = (fundamental.b - fundamental.c) / std::numbers::sqrt3;
  const double magnitude = std::hypot(alpha, beta);
  if (magnitude == 0.0) return fundamental;
  const double psi = std::atan2(beta, alpha);
  const double k = p.k_dt();
  constexpr double kThird = kTwoPi / 3.0;
  return {fundamental.a + phase_distortion(k, magnitude, psi),
          fundamental.b + phase_distortion(k, magnitude, psi - kThird),
          fundamental.c + phase_distortion(k, magnitude, psi + kThird)};
}

DqCurrents dead_time_dq_error(const DeadTime& p, double i_d, double i_q, double theta_e) {
  if (i_d == 0.0 && i_q == 0.0) return {};
  const double delta = std::atan2(i_q, i_d);
  const double ripple = 2.0 * p.k_dt() * std::cos(6.0 * (theta_e + delta));
  return {ripple * i_q, -ripple * i_d};
}

DqCurrents dead_time_ripple_6x(const DeadTime& p, double i_d, double i_q) {
  return {2.0 * p.k_dt() * std::abs(i_q), 2.0 * p.k_dt() * std::abs(i_d)};
}

}  // namespace resolver
