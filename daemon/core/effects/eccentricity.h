// Effect: mechanical eccentricity of the resolver (rotor not concentric with
// the stator, or a bent / runout shaft).
//
// Forward model: the resolver sees the mechanical angle
//   theta_seen_m = theta_m + e sin(theta_m + phase)                      [rad, mechanical]
// and reports theta = p_r theta_seen_m (plus the mounting offset, mounting_offset.h).
// e [rad, mechanical] is the amplitude of the angle error, phase [rad,
// mechanical] the rotor angle where the error crosses zero rising. |e| < 1
// keeps theta_seen_m monotone (catalog limit 0.5; realistic e is ~1e-4..1e-3).
// Signature (docs/ARCHITECTURE.md §7): a 1x MECHANICAL harmonic of the position error,
//   eps_m = theta_m - theta_seen_m = -e sin(theta_m + phase)          [rad, mechanical]
//   eps   = p_r eps_m                                                 [rad, resolver electrical]
// exact as a function of the true angle. In the resolver electrical angle it is
// the subharmonic order 1/p_r, so a fit over theta alone (Hwang, Hanselman
// eq. 9) cannot see it; a fit against the reference angle per mechanical turn
// can. Speed: none in amplitude (geometry); its frequency omega_m is far inside
// any R/D loop's bandwidth. It reaches sin/cos, the R/D angle and everything the
// drive derives from them; the reference encoder and the motor do not see it.
// Compensation: invert theta_seen_m -> theta_m (Kepler-type equation, solved by
// fixed-point iteration, which contracts with factor |e|). To first order
// theta_m ~= theta_seen_m - e sin(theta_seen_m + phase), error <= e^2.
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kEccentricityParams{
    ParamInfo{.name = "e", .unit = "[rad]", .description = "amplitude of the 1x angle error (mechanical rad)",
              .min = -0.5, .max = 0.5, .polar = Polar::kAmplitude},
    ParamInfo{.name = "phase", .unit = "[rad]", .description = "phase of the 1x angle error (mechanical rad)",
              .min = -10.0, .max = 10.0, .polar = Polar::kPhase},
};
using EccentricityParams = ParamSet<kEccentricityParams>;

/// Forward model: the mechanical angle the resolver sees [rad] at true theta_m [rad]
/// (continuous in, continuous out).
[[nodiscard]] double eccentric_angle(const EccentricityParams& p, double theta_m);

/// Position error eps_m = theta_m - theta_seen_m [rad, mechanical] at true theta_m (exact).
[[nodiscard]] double eccentricity_error(const EccentricityParams& p, double theta_m);

/// Compensation: the true mechanical angle [rad] whose eccentric image is theta_seen_m
/// [rad], to |error| <= 1e-15 rad (plus rounding) for |e| <= 0.5. Requires |e| < 1.
[[nodiscard]] double compensate_eccentricity(const EccentricityParams& p, double theta_seen_m);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& eccentricity_effect();

}  // namespace resolver
