#include "daemon/core/effects/eccentricity.h"

#include <cmath>

namespace resolver {

double eccentric_angle(const Eccentricity& p, double theta_m) { return theta_m + p.e * std::sin(theta_m + p.phase); }

double eccentricity_error(const Eccentricity& p, double theta_m) { return -p.e * std::sin(theta_m + p.phase); }

double compensate_eccentricity(const Eccentricity& p, double theta_seen_m) {
  if (!p.active()) return theta_seen_m;
  // theta_m = theta_seen_m - e sin(theta_m + phase): the map's Lipschitz constant is
  // |e|, so each iteration multiplies the error by <= |e|. Starting from theta_seen_m
  // (error <= |e|), 60 iterations reach |e|^61 <= 0.5^61 ~ 4e-19 for |e| <= 0.5; stop
  // early once the update is at rounding level.
  double theta_m = theta_seen_m;
  for (int i = 0; i < 60; ++i) {
    const double next = theta_seen_m - p.e * std::sin(theta_m + p.phase);
    const double change = std::abs(next - theta_m);
    theta_m = next;
    if (change <= 1e-16 * (1.0 + std::abs(theta_seen_m))) break;
  }
  return theta_m;
}

}  // namespace resolver
