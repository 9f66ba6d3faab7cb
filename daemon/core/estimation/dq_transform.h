// Clarke and Park transforms with the project's conventions (docs/ARCHITECTURE.md §3):
//   Clarke, amplitude-invariant:  i_alpha = i_a,  i_beta = (i_b - i_c) / sqrt(3)
//   Park:  i_d =  i_alpha cos(theta_e) + i_beta sin(theta_e)
//          i_q = -i_alpha sin(theta_e) + i_beta cos(theta_e)
// Each transform is a tiny struct computed in its constructor (moteus foc.h style).
#pragma once

#include <cmath>
#include <numbers>

namespace resolver {

/// Amplitude-invariant Clarke transform of three phase currents [A].
struct ClarkeTransform {
  double alpha;  ///< [A]
  double beta;   ///< [A]
  ClarkeTransform(double i_a, double i_b, double i_c)
      : alpha(i_a), beta((i_b - i_c) * (1.0 / std::numbers::sqrt3)) {}
};

/// Park transform of (alpha, beta) currents [A] into the frame at theta_e [rad].
struct ParkTransform {
  double d;  ///< [A]
  double q;  ///< [A]
  ParkTransform(double alpha, double beta, double theta_e)
      : ParkTransform(alpha, beta, std::cos(theta_e), std::sin(theta_e)) {}
  /// With precomputed cos/sin of theta_e (the pipeline evaluates three angles per sample).
  ParkTransform(double alpha, double beta, double cos_e, double sin_e)
      : d(alpha * cos_e + beta * sin_e), q(-alpha * sin_e + beta * cos_e) {}
};

}  // namespace resolver
