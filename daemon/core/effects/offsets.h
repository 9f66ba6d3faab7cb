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

#include "daemon/core/effects/sin_cos.h"

namespace resolver {

struct Offsets {
  double o_s = 0.0;  ///< [fraction of amplitude] offset of the sin channel (range: kParams in offsets.cpp)
  double o_c = 0.0;  ///< [fraction of amplitude] offset of the cos channel (range: kParams in offsets.cpp)
  [[nodiscard]] bool active() const { return o_s != 0.0 || o_c != 0.0; }
};

/// Forward model: adds the offsets to the envelopes.
[[nodiscard]] SinCos apply_offsets(const Offsets& p, const SinCos& in);

/// Small-offset position error eps = theta - phi [rad] at resolver angle theta [rad].
[[nodiscard]] double offsets_error(const Offsets& p, double theta);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& offsets_effect();

}  // namespace resolver
