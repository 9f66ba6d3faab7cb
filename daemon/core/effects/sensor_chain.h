// The resolver sensor chain: every catalog effect's parameters in one plain
// struct, and the composed forward model.
//
// Data flow of the physical chain this models (one sample):
//
//   true theta_m --p_r--> theta --windings--> envelopes --R/D loop--> phi --quantize--> rd_angle
//                 \--p---> theta_e --ideal current control--> i_a, i_b, i_c     \--ADC + noise--> sin/cos counts
//
// Composition order of the envelope effects (physical order, outermost last):
//   1. windings: fundamental {sin theta, cos(theta + beta)}       (quadrature, Hanselman eq. 6)
//                + K_0 + sum K_n {sin n theta, cos n theta}       (harmonics, Hanselman eq. 8)
//   2. channel gain: cos channel x (1 + alpha)                    (amplitude imbalance, Hanselman eq. 16)
//   3. offsets: + o_s, + o_c                                      (after demodulation)
// Quadrature shifts the fundamental only; all cross terms are second order.
// Noise, tracking loop and quantization act after the envelopes and are applied
// by the simulator (tools/sim), which owns the time axis and the random engine.
//
// Defaults are the ideal chain: every effect inactive, an ideal converter
// (tracking_loop.omega_n = 0), 16-bit quantization (the u16 field's own LSB).
#pragma once

#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/effects/harmonics.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/offsets.h"
#include "daemon/core/effects/quadrature.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/core/effects/sin_cos.h"
#include "daemon/core/effects/tracking_loop.h"

namespace resolver {

struct SensorChainConfig {
  AmplitudeImbalance amplitude_imbalance;
  Quadrature quadrature;
  Offsets offsets;
  Harmonics harmonics;
  TrackingLoopConfig tracking_loop;
  Quantization quantization;
  Noise noise;
};

/// Unit-amplitude sin/cos envelopes of the resolver electrical angle theta [rad]
/// with every envelope effect of `config` applied, before noise. Cannot fail.
[[nodiscard]] SinCos sensor_envelopes(const SensorChainConfig& config, double theta);

/// Sum of the active envelope effects' small-parameter position-error signatures
/// eps = theta - phi [rad] at resolver angle theta [rad] (first order, so the
/// signatures superpose). Excludes tracking-loop dynamics, quantization and noise.
[[nodiscard]] double small_signal_error(const SensorChainConfig& config, double theta);

}  // namespace resolver
