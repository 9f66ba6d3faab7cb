// The resolver sensor chain: every catalog effect's parameters in one plain
// struct, and the composed forward model.
//
// Data flow of the physical chain this models (one sample):
//
//   true theta_m --eccentricity, mounting offset--> theta_seen_m --p_r--> theta --windings--> envelopes
//        |                                                                 envelopes --R/D loop--> phi --quantize--> rd_angle
//        |                                                                 envelopes --sampling skew, ADC + noise--> sin/cos counts
//        \--p--> theta_e --drive (mounting offset) + inverter (dead time)--> machine currents
//                                          --sensors (gain mismatch, offsets) + noise--> i_a, i_b, i_c
//
// Resolver angle (resolver_angle): theta = p_r (theta_m + e sin(theta_m + phase) + theta_0 / p)
//   (eccentricity.h, mounting_offset.h). The reference encoder sees theta_m itself.
// Composition order of the envelope effects (physical order, outermost last):
//   1. windings: fundamental {sin theta, cos(theta + beta)}       (quadrature, Hanselman eq. 6)
//                + K_0 + sum K_n {sin n theta, cos n theta}       (harmonics, Hanselman eq. 8)
//   2. channel gain: cos channel x (1 + alpha)                    (amplitude imbalance, Hanselman eq. 16)
//   3. offsets: + o_s, + o_c                                      (after demodulation)
//   4. DSP sampling: cos channel taken tau after sin              (sampling skew; the R/D converter does not see it)
// Quadrature shifts the fundamental only; all cross terms are second order.
// Currents (phase_currents_true, phase_currents_measured):
//   1. drive: the command (i_d*, i_q*) in the drive frame theta_e + theta_0    (mounting_offset.h)
//   2. inverter: + 5th/7th distortion                                          (dead_time.h)
//   3. sensors a, b: x (1 + gain), then + offset                               (current_gain_mismatch.h, current_offsets.h)
// Noise, tracking loop and quantization act after the envelopes and are applied
// by the simulator (tools/sim), which owns the time axis and the random engine.
//
// Defaults are the ideal chain: every effect inactive, an ideal converter
// (tracking_loop.omega_n = 0), 16-bit quantization (the u16 field's own LSB).
#pragma once

#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/effects/current_gain_mismatch.h"
#include "daemon/core/effects/current_offsets.h"
#include "daemon/core/effects/dead_time.h"
#include "daemon/core/effects/eccentricity.h"
#include "daemon/core/effects/harmonics.h"
#include "daemon/core/effects/mounting_offset.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/offsets.h"
#include "daemon/core/effects/phase_currents.h"
#include "daemon/core/effects/quadrature.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/core/effects/sampling_skew.h"
#include "daemon/core/effects/sin_cos.h"
#include "daemon/core/effects/tracking_loop.h"

namespace resolver {

struct SensorChainConfig {
  AmplitudeImbalance amplitude_imbalance;
  Quadrature quadrature;
  Offsets offsets;
  Harmonics harmonics;
  SamplingSkew sampling_skew;
  TrackingLoopConfig tracking_loop;
  Quantization quantization;
  Eccentricity eccentricity;
  MountingOffset mounting_offset;
  CurrentOffsets current_offsets;
  CurrentGainMismatch current_gain_mismatch;
  DeadTime dead_time;
  Noise noise;
};

/// Unit-amplitude sin/cos envelopes of the resolver electrical angle theta [rad]
/// with every envelope effect of `config` applied, before noise. Cannot fail.
[[nodiscard]] SinCos sensor_envelopes(const SensorChainConfig& config, double theta);

/// The envelopes the DSP samples [1]: the sin channel of sensor_envelopes at
/// theta_at_sin [rad] (the sample instant t), the cos channel at theta_at_cos [rad]
/// (the resolver angle at t + sampling_skew.tau). Cannot fail.
[[nodiscard]] SinCos sampled_envelopes(const SensorChainConfig& config, double theta_at_sin, double theta_at_cos);

/// The resolver electrical angle [rad, continuous] the resolver sees at the true
/// mechanical angle theta_m [rad]: p_r (eccentric_angle(theta_m) + theta_0 / p).
/// p_r, p >= 1 (not checked). Cannot fail.
[[nodiscard]] double resolver_angle(const SensorChainConfig& config, double theta_m, int p_r, int p);

/// The phase currents [A] the machine carries at true motor electrical angle theta_e
/// [rad] for the command (i_d_cmd, i_q_cmd) [A]: ideal control in the drive frame
/// theta_e + theta_0, plus the dead-time distortion. Cannot fail.
[[nodiscard]] PhaseCurrents phase_currents_true(const SensorChainConfig& config, double i_d_cmd, double i_q_cmd,
                                                double theta_e);

/// The phase currents [A] the sensors report for the machine currents `actual`
/// (gain mismatch, then offsets), before noise. Cannot fail.
[[nodiscard]] PhaseCurrents phase_currents_measured(const SensorChainConfig& config, const PhaseCurrents& actual);

/// Sum of the active envelope effects' small-parameter position-error signatures
/// eps = theta - phi [rad] at resolver angle theta [rad] (first order, so the
/// signatures superpose). Excludes tracking-loop dynamics, quantization and noise.
[[nodiscard]] double small_signal_error(const SensorChainConfig& config, double theta);

/// small_signal_error plus the sampling skew's signature at constant resolver
/// electrical speed omega [rad/s]: the first-order error of the angle computed
/// from the DSP's sin/cos samples (the R/D angle has small_signal_error only).
[[nodiscard]] double small_signal_sampled_error(const SensorChainConfig& config, double theta, double omega);

}  // namespace resolver
