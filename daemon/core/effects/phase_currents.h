// Phase currents under ideal current control.
//
// Hwang eqs. 11-12 set up the analysis with currents that are perfect
// sinusoids of the TRUE electrical angle: the current controller is assumed
// ideal, so the machine carries exactly the commanded (i_d, i_q) in the true
// rotor frame, and any dq ripple seen by the drive comes from the angle it uses.
// Conventions (docs/ARCHITECTURE.md §3, written once in daemon/core/angles.h):
//   Clarke (amplitude invariant): i_alpha = i_a, i_beta = (i_b - i_c)/sqrt(3)
//   Park: i_d = i_alpha cos theta_e + i_beta sin theta_e
//         i_q = -i_alpha sin theta_e + i_beta cos theta_e
// This file provides the inverse: inverse Park, then inverse Clarke with
// i_a + i_b + i_c = 0.
#pragma once

namespace resolver {

/// Three phase currents [A].
struct PhaseCurrents {
  double a = 0.0;
  double b = 0.0;
  double c = 0.0;
};

/// A current vector in a rotating (d, q) frame [A].
struct DqCurrents {
  double d = 0.0;
  double q = 0.0;
};

/// Phase currents [A] that carry exactly (i_d, i_q) [A] in the frame at the true
/// motor electrical angle theta_e [rad]. Cannot fail.
[[nodiscard]] PhaseCurrents ideal_phase_currents(double i_d, double i_q, double theta_e);

}  // namespace resolver
