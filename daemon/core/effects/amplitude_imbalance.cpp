#include "daemon/core/effects/amplitude_imbalance.h"

#include <cmath>

namespace resolver {

SinCos apply_amplitude_imbalance(const AmplitudeImbalance& p, const SinCos& in) {
  return {in.s, (1.0 + p.alpha) * in.c};
}

double amplitude_imbalance_error(const AmplitudeImbalance& p, double theta) {
  return 0.5 * p.alpha * std::sin(2.0 * theta);
}

}  // namespace resolver
