// The older estimators' results as Models of the registry's effects (issue 22: one
// parameter type, one compensation path). Hwang's integral, the sin/cos least
// squares and the Fourier reference each estimate parameters of catalog effects;
// written as a Model, their result is published, saved and compensated exactly like
// the live model fit's (compensator.h inverts it), and no parameter name is typed
// outside the effect that owns it: each value is looked up in its effect's
// parameter list (a name the effect lacks is a programming error, std::logic_error).
#pragma once

#include "daemon/core/estimation/angle_error_fourier.h"
#include "daemon/core/estimation/sincos_least_squares.h"
#include "daemon/core/model/model.h"

namespace resolver {

/// Hwang's integral estimate: amplitude_imbalance(alpha).
[[nodiscard]] Model hwang_model(double alpha, double alpha_std_error, int p_r, int p);

/// The sin/cos least squares: amplitude_imbalance, quadrature, offsets and, with a
/// reference, the harmonics k_n it fitted (the same envelope definitions: SinCosFit
/// documents each against its effect).
[[nodiscard]] Model sincos_model(const SinCosFit& fit, int p_r, int p);

/// The highest error order of a Fourier reference series a Model can hold: order m
/// lands on the harmonics effect's k_(m+1), and the catalog ends at k20.
inline constexpr int kFourierModelMaxOrder = 19;

/// The Fourier reference series eps(theta) = a_0 + sum a_n sin n theta + b_n cos n theta
/// (angle_error_fourier.h) mapped to the catalog at first order in eps, as its header
/// derives: order 1 -> offsets (o_c = a_1, o_s = -b_1), order 2 -> amplitude_imbalance
/// (alpha = 2 a_2 / (1 - a_2), exact for alpha alone) and quadrature (beta = 2 b_2),
/// order m >= 3 -> harmonics (k_(m+1) = -a_m, k_(m+1)_q = -b_m, Hanselman eq. 9), the
/// constant a_0 + beta/2 -> mounting_offset (eps = -(p_r/p) theta_0). The series is
/// written in the measured angle and the Model in the true one; they differ at second
/// order in eps (a 1e-3 rad error: ~1e-6 rad). Orders above kFourierModelMaxOrder are
/// left out (DaemonConfig refuses such a max_order for this method).
[[nodiscard]] Model fourier_model(const AngleErrorFit& fit, int p_r, int p);

}  // namespace resolver
