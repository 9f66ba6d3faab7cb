#include "daemon/core/effects/harmonics.h"

#include <cmath>
#include <numbers>

namespace resolver {

bool Harmonics::active() const {
  if (k0 != 0.0) return true;
  for (double kn : k) {
    if (kn != 0.0) return true;
  }
  return false;
}

SinCos harmonics_part(const Harmonics& p, double theta) {
  SinCos out{p.k0, p.k0};
  for (int n = 2; n <= Harmonics::kMaxOrder; ++n) {
    const double kn = p.k[static_cast<std::size_t>(n)];
    if (kn == 0.0) continue;
    const double nt = static_cast<double>(n) * theta;
    out.s += kn * std::sin(nt);
    out.c += kn * std::cos(nt);
  }
  return out;
}

double harmonics_error(const Harmonics& p, double theta) {
  double eps = -std::numbers::sqrt2 * p.k0 * std::cos(theta + 0.25 * std::numbers::pi);
  for (int n = 2; n <= Harmonics::kMaxOrder; ++n) {
    const double kn = p.k[static_cast<std::size_t>(n)];
    if (kn == 0.0) continue;
    eps -= kn * std::sin(static_cast<double>(n - 1) * theta);
  }
  return eps;
}

}  // namespace resolver
