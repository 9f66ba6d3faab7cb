#include "daemon/core/effects/sensor_chain.h"

namespace resolver {

SinCos sensor_envelopes(const SensorChainConfig& config, double theta) {
  SinCos sc = quadrature_fundamental(config.quadrature, theta);
  if (config.harmonics.active()) {
    const SinCos h = harmonics_part(config.harmonics, theta);
    sc.s += h.s;
    sc.c += h.c;
  }
  sc = apply_amplitude_imbalance(config.amplitude_imbalance, sc);
  return apply_offsets(config.offsets, sc);
}

double small_signal_error(const SensorChainConfig& config, double theta) {
  return amplitude_imbalance_error(config.amplitude_imbalance, theta) + quadrature_error(config.quadrature, theta) +
         offsets_error(config.offsets, theta) + harmonics_error(config.harmonics, theta);
}

}  // namespace resolver
