// Effect: common-mode drift of the envelope gain in time (the excitation amplitude).
//
// Cause: the excitation warms up. A voltage-driven primary winding draws less
// current as its copper heats (resistance +0.39 %/K), and the excitation amplifier's
// gain drifts with its own temperature; both secondaries are induced by the one
// primary flux, so the sin and cos envelopes change together (Hanselman eq. 1:
// V_s = V_1 sin theta, V_c = V_1 cos theta with one V_1). Over the minutes of a
// thermal time constant a log of seconds sees the slope of the warm-up: a few K per
// minute give |g| ~ 1e-4 /s, a fast warm-up ~1e-3 /s.
// Forward model: s -> (1 + g t) s, c -> (1 + g t) c, t [s] the time since the log's
// first sample, at the windings' gain stage (after the winding harmonics, which the
// same excitation drives; before the demodulated offsets, which it does not).
// Signature: atan2 does not see a common positive factor, so the R/D angle's and the
// sin/cos angle's errors are exactly 0; the radius sqrt(s^2 + c^2) gains g t:
//   rd = 0,   sa = 0,   sr = (1 + g t)(1 + r) - 1 ~= r + g t
// with r the other effects' radius deviation. The column is t on the radius only
// (the fit's y_sr rows); the omitted cross term is g t r. Its mean over the angle
// (r-bar = alpha/2 for an imbalance) is collinear with the column, so the fitted g is
// g (1 + r-bar): 0.15 % high at alpha = 0.003 (the hidden-effect matrix sees exactly
// that), 2.5 % at alpha = 0.05; the rest, g t (r - r-bar), stays below
// g t alpha/2 = 4.5e-6 at g = 1e-3 /s over 3 s (0.06x the 16-bit bench's sin/cos
// floor) and leaves the fit at its floor. The R/D loop's gain scales with the amplitude
// too (its error signal is V_1 sin(theta - phi), tracking_loop.h), a relative change
// g t of an already small lag, not modelled.
//
// Time origin: t counts from the first sample the fit sees (the log's, or a live
// window's). A log that starts t0 later sees (1 + g (t0 + t)) = (1 + g t0)(1 + g' t),
// g' = g / (1 + g t0): the constant (1 + g t0) is the envelopes' unknown amplitude
// (the fit's nuisance.sincos_gain, prepare's median radius) and is absorbed there,
// so the origin does not matter; g is the drift relative to the amplitude at the
// first fitted sample (g' ~= g (1 - g t0): a 1e-3 difference per second of origin at
// g = 1e-3 /s). Only the radius sees it: a log without sin/cos cannot.
//
// Not the simulator's alpha_drift_per_s (tools/sim/bench_simulator.h): that one is a
// DIFFERENTIAL drift (the cos channel alone, a 2 theta angle error growing in time)
// kept outside the catalog on purpose; its common-mode part (the mean radius
// 1 + alpha/2 drifts) is what this effect can take from it, never the angle error.
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h). g's range: ten times the
/// fastest realistic warm-up (~1e-3 /s, above), as the other effects' ranges leave
/// room above the realistic, so the fit is never held at a bound by a real log.
inline constexpr std::array kEnvelopeDriftParams{
    ParamInfo{.name = "g", .unit = "[1/s]",
              .description = "drift rate of the common sin/cos gain: both x (1 + g t), t from the first sample",
              .min = -0.01, .max = 0.01},
};
using EnvelopeDriftParams = ParamSet<kEnvelopeDriftParams>;

/// Forward model: both envelopes scaled by (1 + g t), t [s] since the log's first sample.
[[nodiscard]] SinCos apply_envelope_drift(const EnvelopeDriftParams& p, double t, const SinCos& in);

/// The radius deviation sqrt(s^2 + c^2) - 1 of ideal envelopes under the drift at time t [s]
/// (exactly g t; the position error is exactly 0).
[[nodiscard]] double envelope_drift_radius(const EnvelopeDriftParams& p, double t);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& envelope_drift_effect();

}  // namespace resolver
