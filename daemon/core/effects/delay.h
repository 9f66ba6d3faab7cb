// Effect: a common delay of the resolver signals against the reference.
//
// Cause: fieldbus or scope latency, a filter's group delay, the demodulator's
// common group delay: every resolver signal (sin/cos envelopes and R/D angle) is
// the one of time t - d, while the reference encoder and the currents are not late.
// Forward model: the whole resolver chain is evaluated at t - d.
// Signature, at resolver electrical speed omega (acceleration a):
//   eps = theta(t) - theta(t - d) + e(theta(t - d)) = omega d - a d^2/2 + e(theta - omega d)
// where e is every other effect's error: the delay adds a term proportional to
// speed AND shifts the phase of every error harmonic by k omega d. It is told from
// a constant offset (mounting_offset.h) by a change of speed, and from backlash
// (backlash.h) by a change of |speed|: both flip sign with the direction.
// The envelopes turn with the late angle: s = sin(theta - omega d) ...
// d enters the other effects' columns, so the fit treats it as nonlinear.
#pragma once

namespace resolver {

class Effect;
/// The registry unit of this effect (registry.h).
[[nodiscard]] const Effect& delay_effect();

}  // namespace resolver
