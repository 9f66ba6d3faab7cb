// Effect: amplitude imbalance between the resolver's sin and cos channels.
//
// Cause: different transformer ratios of the two secondaries, unbalanced
// excitation, different analog gains (Hwang section 1).
// Forward model (Hanselman eq. 4, Hwang eq. 6): the cos channel is scaled by
// (1 + alpha), the sin channel is untouched.
// Signature (Hanselman eq. 5, Hwang eq. 10), eps = theta - phi:
//   eps ~= (alpha/2) sin(2 theta)          error at 2x the resolver angle.
// Exactly, phi = atan2(sin theta, (1 + alpha) cos theta); the omitted terms are
// O(alpha^2) (a 2theta amplitude change of alpha^2/4 and a 4theta term of
// alpha^2/8), see tests/unit/effects for the bound.
#pragma once

#include <array>
#include <string>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kAmplitudeImbalanceParams{
    ParamInfo{.name = "alpha", .unit = "[1]", .description = "relative gain error of the cos channel", .min = -0.5,
              .max = 0.5},
};
using AmplitudeImbalanceParams = ParamSet<kAmplitudeImbalanceParams>;

/// Forward model: returns `in` with the cos channel scaled by (1 + alpha).
[[nodiscard]] SinCos apply_amplitude_imbalance(const AmplitudeImbalanceParams& p, const SinCos& in);

/// Small-alpha position error eps = theta - phi [rad] at resolver angle theta [rad]
/// (Hanselman eq. 5, Hwang eq. 10).
[[nodiscard]] double amplitude_imbalance_error(const AmplitudeImbalanceParams& p, double theta);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& amplitude_imbalance_effect();
/// "amplitude_imbalance.alpha": alpha's name in estimate_t, the calibration and the
/// reports (the run report's headline alpha looks it up by this).
[[nodiscard]] std::string amplitude_imbalance_alpha_name();

}  // namespace resolver
