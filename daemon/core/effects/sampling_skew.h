// Effect: skew between the sampling instants of the sin and cos channels.
//
// Cause: the DSP converts the two demodulated envelopes one after the other
// (one multiplexed ADC, or two ADCs triggered apart), so the cos sample of
// control period k is taken tau [s] after the sin sample. The sample's time
// stamp is the sin instant t; the true angle is theta(t).
// Forward model: s = S(theta(t)), c = C(theta(t + tau)), where S, C are the
// envelopes of the rest of the chain (sensor_chain.h) and theta(.) the resolver
// electrical angle [rad] of the moving rotor. tau < 0: cos sampled first.
// Signature (docs/ARCHITECTURE.md §7): at constant resolver electrical speed omega [rad/s],
// theta(t + tau) = theta + omega tau exactly, so the fundamental is
//   {sin theta, cos(theta + beta)}  with  beta = omega tau       (like quadrature)
//   eps = theta - phi ~= -(beta/2)(1 - cos 2theta)              (quadrature.h)
// i.e. a DC part and a 2theta part, both proportional to speed. Under an
// acceleration a [rad/s^2] the cos angle is off the quadrature picture by a tau^2/2.
// Which angle it reaches: only the angle the DSP computes from its sin/cos
// samples. The R/D converter demodulates the analog signals continuously and
// does not see the DSP's sampling skew; that is what tells skew apart from a
// real winding misalignment (quadrature), which both angles carry.
// Compensation: with a speed estimate omega_hat, undo the equivalent quadrature
// on the sampled pair, c_corr = (c + s sin beta) / cos beta, beta = omega_hat tau
// (exact for the fundamental at constant speed; residual O(tau |omega - omega_hat|)).
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kSamplingSkewParams{
    ParamInfo{.name = "tau", .unit = "[s]", .description = "delay of the DSP's cos sample after the sin sample",
              .min = -1e-3, .max = 1e-3},
};
using SamplingSkewParams = ParamSet<kSamplingSkewParams>;

/// Forward model: the sampled pair, sin channel from the envelopes at the sin
/// instant, cos channel from the envelopes at the cos instant (t + tau).
[[nodiscard]] inline SinCos apply_sampling_skew(const SinCos& at_sin_instant, const SinCos& at_cos_instant) {
  return {at_sin_instant.s, at_cos_instant.c};
}

/// [rad] the equivalent quadrature error beta = omega tau at resolver electrical
/// speed omega [rad/s] (docs/ARCHITECTURE.md §7). Grows linearly with speed.
[[nodiscard]] double sampling_skew_beta(const SamplingSkewParams& p, double omega);

/// Small-(omega tau) position error eps = theta - phi [rad] of the angle computed
/// from the sampled sin/cos at resolver angle theta [rad] and constant speed
/// omega [rad/s]: -(omega tau / 2)(1 - cos 2theta). Omitted terms O((omega tau)^2).
[[nodiscard]] double sampling_skew_error(const SamplingSkewParams& p, double theta, double omega);

/// Compensation: the sampled pair with the cos channel moved back to the sin
/// instant, assuming constant speed omega_hat [rad/s] and a sinusoidal fundamental.
/// Requires |omega_hat tau| < pi/2 (not checked).
[[nodiscard]] SinCos compensate_sampling_skew(const SamplingSkewParams& p, const SinCos& sampled,
                                             double omega_hat);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& sampling_skew_effect();

}  // namespace resolver
