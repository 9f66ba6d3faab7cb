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

SinCos sampled_envelopes(const SensorChainConfig& config, double theta_at_sin, double theta_at_cos) {
  const SinCos at_sin = sensor_envelopes(config, theta_at_sin);
  if (!config.sampling_skew.active()) return at_sin;
  return apply_sampling_skew(at_sin, sensor_envelopes(config, theta_at_cos));
}

double resolver_angle(const SensorChainConfig& config, double theta_m, int p_r, int p) {
  return static_cast<double>(p_r) * eccentric_angle(config.eccentricity, theta_m) +
         mounting_offset_resolver_shift(config.mounting_offset, p_r, p);
}

PhaseCurrents phase_currents_true(const SensorChainConfig& config, double i_d_cmd, double i_q_cmd, double theta_e) {
  const PhaseCurrents fundamental =
      ideal_phase_currents(i_d_cmd, i_q_cmd, theta_e + config.mounting_offset.theta_0);
  return apply_dead_time(config.dead_time, fundamental);
}

PhaseCurrents phase_currents_measured(const SensorChainConfig& config, const PhaseCurrents& actual) {
  return apply_current_offsets(config.current_offsets,
                               apply_current_gain_mismatch(config.current_gain_mismatch, actual));
}

double small_signal_error(const SensorChainConfig& config, double theta) {
  return amplitude_imbalance_error(config.amplitude_imbalance, theta) + quadrature_error(config.quadrature, theta) +
         offsets_error(config.offsets, theta) + harmonics_error(config.harmonics, theta);
}

double small_signal_sampled_error(const SensorChainConfig& config, double theta, double omega) {
  return small_signal_error(config, theta) + sampling_skew_error(config.sampling_skew, theta, omega);
}

}  // namespace resolver
