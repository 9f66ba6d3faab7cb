// Effect: offsets of the phase current sensors.
//
// The DSP measures all three phases (the layout of docs/ARCHITECTURE.md §4 sends i_a, i_b, i_c). Offsets are
// modelled on the a and b sensors only; c is the reference (any common offset of
// all three is a zero-sequence term that the Clarke transform of docs/ARCHITECTURE.md §3 does
// not fully remove, so keeping c clean makes off_a, off_b the two observable
// parameters). They act on the MEASUREMENT: the machine carries the controlled
// current (Hwang's ideal-control picture, phase_currents.h).
// Forward model: i_a_meas = i_a + off_a, i_b_meas = i_b + off_b, i_c_meas = i_c [A].
// Signature (docs/ARCHITECTURE.md §7): through Clarke (i_alpha = i_a, i_beta = (i_b - i_c)/sqrt3)
// the offsets are a constant stationary vector (off_a, off_b/sqrt3); in the
// rotating frame it turns at -theta_e:
//   delta i_d =  off_a cos theta_e + (off_b/sqrt3) sin theta_e
//   delta i_q = -off_a sin theta_e + (off_b/sqrt3) cos theta_e
// a 1x theta_e ripple of amplitude hypot(off_a, off_b/sqrt3) on each of i_d and
// i_q, a quarter period apart. Exact (linear); independent of the load current
// and of speed except that its frequency is omega_e. The phase sum
// i_a + i_b + i_c = off_a + off_b also exposes it.
// Compensation: subtract the offsets (measured at zero current).
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/phase_currents.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kCurrentOffsetsParams{
    ParamInfo{.name = "off_a", .unit = "[A]", .description = "offset of the phase a current sensor", .min = -1000.0,
              .max = 1000.0},
    ParamInfo{.name = "off_b", .unit = "[A]", .description = "offset of the phase b current sensor", .min = -1000.0,
              .max = 1000.0},
};
using CurrentOffsetsParams = ParamSet<kCurrentOffsetsParams>;

/// Forward model: the measured phase currents [A].
[[nodiscard]] PhaseCurrents apply_current_offsets(const CurrentOffsetsParams& p, const PhaseCurrents& in);

/// Signature: the dq error [A] the offsets add in the frame at theta_e [rad] (exact).
[[nodiscard]] DqCurrents current_offsets_dq_error(const CurrentOffsetsParams& p, double theta_e);

/// [A] amplitude of the 1x theta_e ripple on i_d (and on i_q): hypot(off_a, off_b/sqrt3).
[[nodiscard]] double current_offsets_ripple_1x(const CurrentOffsetsParams& p);

/// Compensation: removes the offsets from measured currents [A].
[[nodiscard]] PhaseCurrents compensate_current_offsets(const CurrentOffsetsParams& p, const PhaseCurrents& measured);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& current_offsets_effect();

}  // namespace resolver
