// Effect: gain mismatch of the phase current sensors.
//
// As for offsets (current_offsets.h) the a and b sensors carry the error and c
// is the reference; it acts on the MEASUREMENT only.
// Forward model: i_a_meas = (1 + gain_a) i_a, i_b_meas = (1 + gain_b) i_b,
// i_c_meas = i_c.
// Signature (docs/ARCHITECTURE.md §7), for ideal currents i_alpha + j i_beta = I e^{j theta_e},
// I = i_d + j i_q (phase_currents.h): i_a = Re(I e^{j theta_e}),
// i_b = Re(I e^{j(theta_e - 2pi/3)}), and the Clarke error
// delta = gain_a i_a + j gain_b i_b / sqrt3, rotated by e^{-j theta_e}, is
//   delta_dq = I   (gain_a + gain_b/2 - j gain_b/(2 sqrt3)) / 2                    (DC)
//            + I* (gain_a - gain_b/2 - j gain_b/(2 sqrt3)) / 2 e^{-j 2 theta_e}    (2x)
// so i_d and i_q each carry a 2x theta_e ripple of amplitude
//   A_2 = |I| / 2 sqrt((gain_a - gain_b/2)^2 + gain_b^2 / 12)
// plus a DC shift. Exact (linear in the gains), proportional to the current,
// independent of speed except for its frequency 2 omega_e. When p_r = p it lands
// on the same frequency as the resolver's amplitude imbalance (Hwang eq. 15-16):
// only the resolver signals tell them apart (docs/ARCHITECTURE.md §7).
// Compensation: divide the measured a, b currents by (1 + gain).
//
// In the fit the operating current is the MEASURED mean (SignatureRow::i_d0, the d and q
// constants): I (1 + c) with c the DC factor above, not the machine's I. Taking the ripple
// at the measured mean, as a first-order column does, scales and turns it by 1 + c: at
// gains of 3 % and -2 % that biased gain_a by 1.8 % (0.0295 for 0.03, 9 standard errors).
// The fit's prediction solves I from the measured mean at the current gains instead
// (current_gain_mismatch_operating_point), exact at any magnitude, and its columns are
// the derivatives of that prediction.
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/phase_currents.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kCurrentGainMismatchParams{
    ParamInfo{.name = "gain_a", .unit = "[1]", .description = "relative gain error of the phase a current sensor",
              .min = -0.5, .max = 0.5},
    ParamInfo{.name = "gain_b", .unit = "[1]", .description = "relative gain error of the phase b current sensor",
              .min = -0.5, .max = 0.5},
};
using CurrentGainMismatchParams = ParamSet<kCurrentGainMismatchParams>;

/// Forward model: the measured phase currents [A].
[[nodiscard]] PhaseCurrents apply_current_gain_mismatch(const CurrentGainMismatchParams& p, const PhaseCurrents& in);

/// Signature: the dq error [A] in the frame at theta_e [rad] when the machine carries
/// (i_d, i_q) [A] in that frame (ideal currents). Exact.
[[nodiscard]] DqCurrents current_gain_mismatch_dq_error(const CurrentGainMismatchParams& p, double i_d,
                                                        double i_q, double theta_e);

/// The machine's operating current (i_d, i_q) [A] whose measured mean, DC error of the
/// gains included, is `measured` [A]: solves measured = I + DC(I), a 2x2 linear system.
[[nodiscard]] DqCurrents current_gain_mismatch_operating_point(const CurrentGainMismatchParams& p,
                                                               DqCurrents measured);

/// [A] amplitude A_2 of the 2x theta_e ripple on i_d (and on i_q) at current (i_d, i_q) [A].
[[nodiscard]] double current_gain_mismatch_ripple_2x(const CurrentGainMismatchParams& p, double i_d, double i_q);

/// Compensation: undoes the gains on measured currents [A] .
[[nodiscard]] PhaseCurrents compensate_current_gain_mismatch(const CurrentGainMismatchParams& p,
                                                             const PhaseCurrents& measured);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& current_gain_mismatch_effect();

}  // namespace resolver
