#include "daemon/core/effects/phase_currents.h"

#include <cmath>
#include <numbers>

namespace resolver {

PhaseCurrents ideal_phase_currents(double i_d, double i_q, double theta_e) {
  const double ce = std::cos(theta_e);
  const double se = std::sin(theta_e);
  // Inverse Park: the transpose of the rotation in docs/ARCHITECTURE.md §3.
  const double i_alpha = i_d * ce - i_q * se;
  const double i_beta = i_d * se + i_q * ce;
  // Inverse amplitude-invariant Clarke with zero sum: i_b - i_c = sqrt(3) i_beta,
  // i_b + i_c = -i_alpha.
  const double half_sqrt3_beta = 0.5 * std::numbers::sqrt3 * i_beta;
  return {i_alpha, -0.5 * i_alpha + half_sqrt3_beta, -0.5 * i_alpha - half_sqrt3_beta};
}

}  // namespace resolver
