// Effect: resolver mounting offset (commutation offset).
//
// Definition. The reference encoder's zero is the rotor d axis: the true motor
// electrical angle is theta_e = p theta_m (angles.h). The resolver's zero sits
// theta_0 / p mechanical rad ahead of the d axis, so it reports
//   theta = p_r (theta_m + theta_0 / p)                   [rad, resolver electrical]
// and a drive that derives its electrical angle from the resolver (Hwang eq. 19,
// theta_e_drive = (p / p_r) theta) and assumes the resolver zero is the d axis uses
//   theta_e_drive = theta_e + theta_0                     [rad, motor electrical].
// theta_0 is therefore in MOTOR electrical rad: the angle by which the drive's
// current frame leads the rotor.
// Forward model (two places):
//   1. the resolver angle is shifted by (p_r / p) theta_0 (sin/cos and R/D angle);
//   2. the drive's current controller puts the commanded (i_d*, i_q*) in ITS frame,
//      so the machine current in the rotor frame is the command rotated by theta_0:
//        i_d = i_d* cos theta_0 - i_q* sin theta_0
//        i_q = i_d* sin theta_0 + i_q* cos theta_0
//      A constant angle error lies inside any current loop's bandwidth, so unlike the
//      ripple effects (Hwang's ideal-control picture, phase_currents.h) it is tracked.
// Signature (docs/ARCHITECTURE.md §7): constant, speed independent.
//   - angle: eps = theta_true - theta_measured = -(p_r / p) theta_0 [rad, resolver electrical]
//     against the reference angle;
//   - dq: with the reference angle, a steady i_d = -i_q* sin theta_0 under a pure i_q
//     command (and i_q reduced by cos theta_0); with the drive's own (raw R/D) angle the
//     currents look perfect, (i_d*, i_q*), which is why it goes unnoticed without a reference.
// Compensation: theta_e_comp = theta_e_drive - theta_0; theta_0 is estimated from the
// reference-frame currents (estimate_mounting_offset) or from the mean eps.
#pragma once

#include <array>

#include "daemon/core/angles.h"
#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/phase_currents.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kMountingOffsetParams{
    ParamInfo{.name = "theta_0", .unit = "[rad]",
              .description = "drive (resolver) zero ahead of the rotor d axis (motor electrical rad)", .min = -kPi,
              .max = kPi},
};
using MountingOffsetParams = ParamSet<kMountingOffsetParams>;

/// Forward model 1: the shift of the resolver electrical angle (p_r / p) theta_0 [rad].
/// p_r, p >= 1 (not checked).
[[nodiscard]] double mounting_offset_resolver_shift(const MountingOffsetParams& m, int p_r, int p);

/// Forward model 2: the commanded current vector (i_d*, i_q*) [A] of the drive frame,
/// expressed in the rotor frame (rotation by theta_0).
[[nodiscard]] DqCurrents mounting_offset_rotor_currents(const MountingOffsetParams& m, double i_d_cmd,
                                                        double i_q_cmd);

/// Signature: the constant position error eps [rad, resolver electrical] against the reference.
[[nodiscard]] double mounting_offset_error(const MountingOffsetParams& m, int p_r, int p);

/// Estimate of theta_0 [rad, motor electrical, in [-pi, pi)] from the steady rotor-frame
/// (reference-angle) currents [A] and the command [A]. Returns 0 when either vector is zero.
[[nodiscard]] double estimate_mounting_offset(double i_d_ref, double i_q_ref, double i_d_cmd, double i_q_cmd);

/// Compensation: the rotor electrical angle [rad] from the drive's theta_e_drive [rad].
[[nodiscard]] double compensate_mounting_offset(const MountingOffsetParams& m, double theta_e_drive);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& mounting_offset_effect();

}  // namespace resolver
