// Effect: inverter dead time, as a SIGNATURE model.
//
// This is not an inverter model. A real dead time t_d adds to each phase
// voltage a square wave -V_dt sign(i_x), V_dt = t_d f_pwm V_dc, and the machine's
// impedance turns its 5th (negative sequence) and 7th (positive sequence)
// harmonics into current harmonics that appear in the rotating frame at 6x
// theta_e (docs/ARCHITECTURE.md §7). Here we keep only that signature, with one constant:
//
//   each phase current gains  delta i_x = k_dt |I| (sin 7 psi_x - sin 5 psi_x)
//   where i_x = |I| cos psi_x is the phase's fundamental and
//   k_dt = t_d / kReferenceTime                                            [1]
//
// Where the shape comes from: for an inductive machine (omega_e L >> R) the
// square wave's harmonics (4 V_dt / pi)(cos 5psi / 5 - cos 7psi / 7) divided by
// j(-5 omega_e) L and j(7 omega_e) L give current harmonics
// -j (4 V_dt / (pi omega_e L)) (e^{-j5psi} / 25 + e^{j7psi} / 49) in the
// stationary frame; the model keeps their phase and sequence and gives both the
// same relative amplitude k_dt, which is the simplification.
// kReferenceTime = 100 us is a convention, not a physical constant: it makes
// a typical 1-2 us dead time of a 10 kHz, few-hundred-volt IGBT inverter give the
// 1-2 % 5th/7th current distortion such drives show at moderate load.
// Also simplified: the amplitude scales with |I| (the real one is set by V_dt
// and the impedance, so it falls ~1/omega_e with speed and does not vanish
// with load) and zero-crossing clamping is ignored.
//
// Signature in dq. In the frame at theta_e with the current vector
// I = i_d + j i_q = |I| e^{j delta}, psi = theta_e + delta, the stationary
// distortion -j k |I| (e^{-j5psi} + e^{j7psi}) becomes
//   delta i_d =  2 k_dt i_q cos(6 (theta_e + delta))
//   delta i_q = -2 k_dt i_d cos(6 (theta_e + delta))
// a 6x theta_e ripple perpendicular to the current vector: a pure-i_q command
// shows it on i_d with amplitude 2 k_dt |i_q|. Speed: none in the model (frequency 6 omega_e).
// It acts on the MACHINE current, so the sensors measure it.
// Compensation: subtract the modelled dq ripple (dead_time_dq_error); a real drive
// would feed the square-wave voltage forward instead.
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/phase_currents.h"

namespace resolver {

/// [s] the dead time that gives k_dt = 1 (see the header comment).
inline constexpr double kDeadTimeReferenceTime = 100e-6;

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kDeadTimeParams{
    // 20 us is already an extreme dead time; it gives k_dt = 0.2 (dead_time.h).
    ParamInfo{.name = "t_d", .unit = "[s]",
              .description = "inverter dead time (5th/7th current harmonics k_dt = t_d / 100 us)", .min = 0.0,
              .max = 2e-5},
};
using DeadTimeParams = ParamSet<kDeadTimeParams>;

/// [1] relative amplitude of each of the 5th and 7th current harmonics, t_d / kDeadTimeReferenceTime.
[[nodiscard]] constexpr double dead_time_k_dt(const DeadTimeParams& p) { return p["t_d"] / kDeadTimeReferenceTime; }

/// Forward model: the phase currents [A] with the 5th/7th distortion added to the
/// balanced fundamental `fundamental` (zero sum). The result still sums to zero.
[[nodiscard]] PhaseCurrents apply_dead_time(const DeadTimeParams& p, const PhaseCurrents& fundamental);

/// Signature: the dq distortion [A] in the frame at theta_e [rad] when the fundamental is
/// (i_d, i_q) [A] in that frame.
[[nodiscard]] DqCurrents dead_time_dq_error(const DeadTimeParams& p, double i_d, double i_q, double theta_e);

/// [A] amplitudes of the 6x theta_e ripple on i_d (2 k_dt |i_q|) and on i_q (2 k_dt |i_d|).
[[nodiscard]] DqCurrents dead_time_ripple_6x(const DeadTimeParams& p, double i_d, double i_q);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& dead_time_effect();

}  // namespace resolver
