// Effect: mechanical harmonics of the angle the resolver sees.
//
// Cause: geometry of the shaft and coupling: eccentricity is order 1, a coupling
// misalignment (angular or parallel) order 2, a flexible coupling's lobes higher
// orders. The resolver sees
//   theta_seen_m = theta_m + sum_n (a_n sin(n theta_m) + b_n cos(n theta_m))   [rad, mechanical]
// Signature (exact as a function of the true angle, like eccentricity.h):
//   eps = -p_r sum_n (a_n sin(n theta_m) + b_n cos(n theta_m))               [rad, resolver electrical]
// i.e. orders n / p_r of theta: only a fit against the reference encoder over whole
// mechanical turns sees them. The envelopes turn with the seen angle.
// Order 1 is eccentricity in Cartesian form (a_1 = e cos phase, b_1 = e sin phase).
#pragma once

namespace resolver {

/// Highest mechanical order the effect has parameters for.
inline constexpr int kMaxMechanicalOrder = 16;

class Effect;
/// The registry unit of this effect (registry.h).
[[nodiscard]] const Effect& mechanical_harmonics_effect();

}  // namespace resolver
