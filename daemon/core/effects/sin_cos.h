// The resolver's demodulated sin/cos envelopes and the angle they encode.
//
// Units: an "envelope" is the demodulated secondary signal divided by the
// nominal amplitude (V_1 in Hanselman eq. 1, K*E in Hwang eqs. 1-2), so an ideal
// resolver gives {sin(theta), cos(theta)} with unit radius. The simulator scales
// by the ADC amplitude [counts] only at the very end.
#pragma once

#include <cmath>

#include "daemon/core/angles.h"

namespace resolver {

/// Unit-amplitude resolver envelopes [1].
struct SinCos {
  double s = 0.0;  ///< sin channel (Hanselman V_s / V_1)
  double c = 1.0;  ///< cos channel (Hanselman V_c / V_1)
};

/// The ideal envelopes of the resolver electrical angle theta [rad] (Hanselman eq. 1).
[[nodiscard]] inline SinCos ideal_envelopes(double theta) { return {std::sin(theta), std::cos(theta)}; }

/// The angle an ideal, infinitely fast R/D converter reads from the envelopes:
/// the equilibrium of Hanselman eq. 3, s*cos(phi) - c*sin(phi) = 0, i.e.
/// atan2(s, c) [rad], wrapped to [0, 2pi). Cannot fail; atan2(0, 0) gives 0.
[[nodiscard]] inline double static_rd_angle(const SinCos& sc) { return wrap_2pi(std::atan2(sc.s, sc.c)); }

/// The R/D error signal of Hanselman eq. 3 / Hwang eq. 8 (divided by V_1):
/// E = s*cos(phi) - c*sin(phi) = sin(theta - phi) for ideal envelopes.
[[nodiscard]] inline double rd_error_signal(const SinCos& sc, double phi) {
  return sc.s * std::cos(phi) - sc.c * std::sin(phi);
}

}  // namespace resolver
