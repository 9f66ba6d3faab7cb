// Effect: backlash (play) between the reference encoder and the resolver.
//
// Cause: play in the coupling between the reference shaft and the resolver rotor,
// a gearbox's backlash, a stepper's lag: the resolver side follows the reference
// only once the gap is taken up, so in steady motion it lags by h/2 in the
// direction of motion (a deadband of width h [rad, mechanical]):
//   theta_seen_m = clamp(previous theta_seen_m, theta_m - h/2, theta_m + h/2)
// Signature (steady motion, gap taken up):
//   eps = p_r (h/2) sign(omega)                                  [rad, resolver electrical]
// an offset that flips with the direction of motion; during the take-up after a
// reversal (h of travel) the resolver stands still. The envelopes turn with the
// seen angle. Only a log with both directions tells it from a constant offset.
#pragma once

namespace resolver {

class Effect;
/// The registry unit of this effect (registry.h).
[[nodiscard]] const Effect& backlash_effect();

}  // namespace resolver
