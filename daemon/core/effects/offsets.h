// Effect: DC offsets on the demodulated sin/cos channels.
//
// Cause: amplifier / ADC offsets after demodulation, imperfect demodulation.
// Forward model: s + o_s, c + o_c (offsets as a fraction of the nominal amplitude).
// Signature: first-order perturbation of phi = atan2(s, c), whose gradient on the
// unit circle is (d phi/d s, d phi/d c) = (cos theta, -sin theta):
//   eps = theta - phi ~= o_c sin(theta) - o_s cos(theta)      error at 1x theta.
// The omitted terms are bounded by |o|^2 / (2 (1 - |o|)^2), |o| = hypot(o_s, o_c)
// (the Hessian of atan2 has norm 1/r^2).
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kOffsetsParams{
    ParamInfo{.name = "o_s", .unit = "[fraction of amplitude]", .description = "DC offset of the sin channel",
              .min = -0.5, .max = 0.5},
    ParamInfo{.name = "o_c", .unit = "[fraction of amplitude]", .description = "DC offset of the cos channel",
              .min = -0.5, .max = 0.5},
};
using OffsetsParams = ParamSet<kOffsetsParams>;

/// Forward model: adds the offsets to the envelopes.
[[nodiscard]] SinCos apply_offsets(const OffsetsParams& p, const SinCos& in);

/// Small-offset position error eps = theta - phi [rad] at resolver angle theta [rad].
[[nodiscard]] double offsets_error(const OffsetsParams& p, double theta);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& offsets_effect();

}  // namespace resolver
