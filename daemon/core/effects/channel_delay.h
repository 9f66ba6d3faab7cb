// Effect: delay mismatch of the analog channels before the R/D converter.
//
// Cause: the cos path's filter or demodulator is slower than the sin path's, so
// both the R/D converter and the DSP see the cos envelope of an earlier instant:
//   s(t) = S(theta(t)),  c(t) = C(theta(t - tau))                       [tau in s]
// At resolver electrical speed omega, theta(t - tau) = theta - omega tau, so the
// pair is quadrature (quadrature.h) with beta = -omega tau, and unlike the DSP's
// sampling skew (sampling_skew.h) the R/D angle shows it too:
//   eps ~= (omega tau / 2)(1 - cos 2theta)                 (first order in omega tau)
//   c - cos theta ~= omega tau sin theta
// It grows with speed, so a log with one speed cannot tell it from quadrature.
#pragma once

namespace resolver {

class Effect;
/// The registry unit of this effect (registry.h).
[[nodiscard]] const Effect& channel_delay_effect();

}  // namespace resolver
