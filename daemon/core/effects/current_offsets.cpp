#include "daemon/core/effects/current_offsets.h"

#include <cmath>
#include <numbers>

namespace resolver {

PhaseCurrents apply_current_offsets(const CurrentOffsets& p, const PhaseCurrents& in) {
  return {in.a + p.off_a, in.b + p.off_b, in.c};
}

DqCurrents current_offsets_dq_error(const CurrentOffsets& p, double theta_e) {
  const double d_alpha = p.off_a;
  const double d_beta = p.off_b / std::numbers::sqrt3;
  const double ce = std::cos(theta_e);
  const double se = std::sin(theta_e);
  return {d_alpha * ce + d_beta * se, -d_alpha * se + d_beta * ce};
}

double current_offsets_ripple_1x(const CurrentOffsets& p) { return std::hypot(p.off_a, p.off_b / std::numbers::sqrt3); }

PhaseCurrents compensate_current_offsets(const CurrentOffsets& p, const PhaseCurrents& measured) {
  return {measured.a - p.off_a, measured.b - p.off_b, measured.c};
}

}  // namespace resolver
