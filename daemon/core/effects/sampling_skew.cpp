#include "daemon/core/effects/sampling_skew.h"

#include <cmath>

namespace resolver {

double sampling_skew_beta(const SamplingSkew& p, double omega) { return omega * p.tau; }

double sampling_skew_error(const SamplingSkew& p, double theta, double omega) {
  // Quadrature signature (quadrature.h) with beta = omega tau.
  return -0.5 * sampling_skew_beta(p, omega) * (1.0 - std::cos(2.0 * theta));
}

SinCos compensate_sampling_skew(const SamplingSkew& p, const SinCos& sampled, double omega_hat) {
  // c = cos(theta + beta) = cos(theta) cos(beta) - sin(theta) sin(beta), s = sin(theta).
  const double beta = sampling_skew_beta(p, omega_hat);
  return {sampled.s, (sampled.c + sampled.s * std::sin(beta)) / std::cos(beta)};
}

}  // namespace resolver
