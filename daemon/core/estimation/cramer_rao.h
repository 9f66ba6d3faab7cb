// Cramer-Rao lower bounds for the sin/cos envelope parameters.
//
// Model (the effect catalog's forward model, daemon/core/effects/sensor_chain.h,
// in signal units [counts]):
//   s_i = A sin(theta_i)                        + A o_s + n_s,i
//   c_i = A (1 + alpha) cos(theta_i + beta)     + A o_c + n_c,i
// n_s, n_c white Gaussian, std sigma [counts] each, independent. Parameters
// x = (A, alpha, beta, o_s, o_c); the bound is evaluated at the nominal point
// alpha = beta = o_s = o_c = 0 (the imperfections are percent-level, so the bound
// at the true point differs by O(alpha, beta) relative; the test checks that).
//
// 1. Known angles (a reference encoder aligned with the sin channel).
//    Fisher information F = (1/sigma^2) sum_i (g_s,i g_s,i^T + g_c,i g_c,i^T) with
//      g_s = ds/dx = (sin t, 0,        0,         A, 0)
//      g_c = dc/dx = (cos t, A cos t, -A sin t,  0, A)          (t = theta_i)
//    For angles spread uniformly over whole revolutions the sample means are
//    <sin^2> = <cos^2> = 1/2 and <sin>, <cos>, <sin cos> = 0, so
//      F sigma^2 / N = [ 1    A/2    0      0    0  ]
//                      [ A/2  A^2/2  0      0    0  ]
//                      [ 0    0      A^2/2  0    0  ]
//                      [ 0    0      0      A^2  0  ]
//                      [ 0    0      0      0    A^2]
//    Inverting the (A, alpha) block (det = A^2/4):
//      var(A) >= 2 sigma^2 / N,   var(alpha) >= 4 sigma^2 / (N A^2),
//      var(beta) >= 2 sigma^2 / (N A^2),   var(o_s), var(o_c) >= sigma^2 / (N A^2).
//    (With A known, var(alpha) >= 2 sigma^2/(N A^2): alpha is the cos amplitude
//    relative to the sin amplitude, and both are estimated, hence the factor 2.)
//    When the reference has an unknown constant offset delta (theta = theta_ref +
//    delta; a real encoder is never aligned to the resolver), add
//      ds/d delta = A cos t,  dc/d delta = -A sin t
//    which couples only with beta: the (beta, delta) block is A^2 [1/2 1/2; 1/2 1],
//    det A^4/4, so var(beta) >= 4 sigma^2/(N A^2), var(delta) >= 2 sigma^2/(N A^2).
//
// 2. Unknown angles ("blind": the conic fit of the (s, c) pairs). Every sample
//    adds a nuisance theta_i with g_theta = (A cos t, -A sin t), tangential to the
//    circle. Eliminating it (Schur complement per sample) keeps only the radial
//    component n = (sin t, cos t) of each gradient:
//      F = (1/sigma^2) sum_i (n^T G_i)^T (n^T G_i),  G_i = [g_s; g_c] (2 x 5)
//      n^T G = (1, A cos^2 t, -A sin t cos t, A sin t, A cos t)
//    With <cos^4> = 3/8, <sin^2 cos^2> = 1/8 and odd moments 0:
//      F sigma^2 / N = diag-blocks [1 A/2; A/2 3A^2/8], A^2/8, A^2/2, A^2/2
//    so var(A) >= 3 sigma^2/N, var(alpha) >= 8 sigma^2/(N A^2),
//       var(beta) >= 8 sigma^2/(N A^2), var(o_s), var(o_c) >= 2 sigma^2/(N A^2).
//    Not knowing the angle costs a factor 2 in variance on alpha and the offsets
//    and 4 on beta (beta only shows as the ellipse's tilt, a sin t cos t pattern).
//
// The bounds are stds (square roots of the variances above). Cannot fail; returns
// NaN fields for n <= 0, amplitude <= 0 or sigma < 0.
#pragma once

#include <cstdint>

namespace resolver {

struct CramerRao {
  double amplitude = 0.0;  ///< [signal units, like sigma] std bound of A
  double alpha = 0.0;      ///< [1]
  double beta = 0.0;       ///< [rad] reference aligned (or blind: the conic's own bound)
  double o_s = 0.0;        ///< [fraction of A]
  double o_c = 0.0;        ///< [fraction of A]
  /// [rad] beta when the reference's constant offset is fitted too (known-angle case only; NaN blind).
  double beta_with_offset = 0.0;
  /// [rad] the reference offset delta itself (known-angle case only; NaN blind).
  double reference_offset = 0.0;
};

/// Bound with known angles (reference): amplitude A [counts], noise std sigma
/// [counts] on each channel, n samples uniformly spread over whole revolutions.
[[nodiscard]] CramerRao crlb_sincos(double amplitude, double sigma, std::int64_t n);

/// Bound with unknown angles (conic / ellipse fit of the (s, c) pairs alone).
[[nodiscard]] CramerRao crlb_sincos_blind(double amplitude, double sigma, std::int64_t n);

}  // namespace resolver
