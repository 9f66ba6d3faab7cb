// Angle-domain Fourier fit of the position error (Hanselman III.A: "the error
// versus position is approximated by a Fourier series", after Hung and Hung).
//
//   eps(theta) = theta_true - theta_rd ~= a_0 + sum_{n=1..N} a_n sin(n theta) + b_n cos(n theta)
//
// The series is written in the MEASURED angle theta = theta_rd, because the
// compensation evaluates it there: theta_c = theta_rd + eps_hat(theta_rd)
// (docs/ARCHITECTURE.md §3). Writing it in the true angle instead changes the coefficients
// only at second order in eps.
//
// Two ways to obtain eps:
//  - with a reference angle: eps_i = wrap_pi(theta_ref,i - theta_rd,i); the fit is
//    a linear LS in [1, sin n theta, cos n theta], accumulated recursively with
//    exponential forgetting (normal equations, as in sincos_least_squares.h);
//  - without one (fit_error_smooth_angle): the true angle is modelled as a
//    low-order polynomial in time over a window of whole revolutions, and fitted
//    JOINTLY with the harmonics:
//      theta_rd,i = sum_{j=0..P} c_j tau_i^j - sum_{n=1..N} (a_n sin n theta_rd,i + b_n cos n theta_rd,i)
//    (tau = time scaled to [-1, 1]). A separate ramp fit would absorb part of the
//    harmonics (sin 2theta is not orthogonal to a ramp over a finite window); the
//    joint fit does not, and a_0 is not identifiable (it is the polynomial's c_0).
//
// Mapping to the effect catalog where identifiable (first order, eps = true - measured):
//   alpha:   eps ~ (alpha/2) sin 2theta  (Hanselman 5). Exactly, for alpha alone the
//            sin 2theta coefficient is q = alpha/(2 + alpha) (tan phi = tan theta/(1+alpha)),
//            so alpha = 2 a_2 / (1 - a_2), which removes the alpha^2/2 relative bias.
//            K_3 also lands here (-K_3 sin 2theta, Hanselman 9): this fit cannot tell
//            them apart; the sin/cos least squares can.
//   beta:    eps ~ -(beta/2)(1 - cos 2theta)  (Hanselman 7 with the sign checked in
//            daemon/core/effects/quadrature.h)  =>  beta = 2 b_2
//            (the constant -beta/2 is confounded with the reference offset).
//   offsets: eps ~ o_c sin theta - o_s cos theta (effects/offsets.h) => o_c = a_1, o_s = -b_1.
//            K_0 lands here too (as o_s = o_c = K_0).
// Standard errors: residual variance times diag((J^T J)^-1) (the delta method for
// the mapped parameters: d alpha/d a_2 = 2/(1 - a_2)^2).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "daemon/core/estimation/sincos_least_squares.h"

namespace resolver {

struct AngleFourierConfig {
  /// Highest harmonic order N fitted (>= 2 for the catalog mapping).
  int max_order = 4;
  /// Forgetting factor of the recursive (reference) fit, in (0, 1].
  double forgetting = 1.0;
  /// Polynomial order P of the ideal angle in time (no-reference fit): 1 = constant
  /// speed, 2 = constant acceleration.
  int poly_order = 2;
  /// Fewest samples before a fit is returned.
  std::int64_t min_samples = 32;
  bool operator==(const AngleFourierConfig&) const = default;
};

struct AngleErrorFit {
  int max_order = 0;
  Estimate a0;                ///< [rad] constant (NaN std without reference: not identifiable)
  std::vector<Estimate> a;    ///< [rad] a[n] multiplies sin(n theta), n = 1..N (a[0] unused)
  std::vector<Estimate> b;    ///< [rad] b[n] multiplies cos(n theta)
  Estimate alpha, beta, o_s, o_c;  ///< catalog mapping (see header)
  double samples = 0.0;            ///< effective number of samples
  double residual_rms = 0.0;       ///< [rad]
  double revolutions = 0.0;        ///< resolver electrical revolutions in the window (no-reference fit)

  /// eps_hat(theta) [rad] at measured angle theta [rad], including a_0.
  [[nodiscard]] double eps(double theta) const;
  /// Compensated angle theta_rd + eps_hat(theta_rd), wrapped to [0, 2pi).
  [[nodiscard]] double compensate(double theta_rd) const;
};

/// Recursive fit of eps = theta_ref - theta_rd against a reference.
class AngleErrorFourier {
 public:
  /// Throws std::invalid_argument when max_order < 1 or forgetting not in (0, 1].
  explicit AngleErrorFourier(const AngleFourierConfig& config);

  /// One sample: reference and R/D resolver electrical angles [rad] (wrapped or not).
  void add(double theta_ref, double theta_rd);
  /// nullopt with fewer than min_samples or when the angles do not cover a revolution.
  [[nodiscard]] std::optional<AngleErrorFit> solve() const;
  void reset();

 private:
  AngleFourierConfig config_;
  Eigen::MatrixXd m_;
  Eigen::VectorXd b_;
  double yy_ = 0.0, w_ = 0.0, w2_ = 0.0;
  std::int64_t seen_ = 0;
};

/// Batch fit without reference over samples t [s] and theta_rd [rad] (wrapped or
/// continuous; unwrapped inside). Uses the longest prefix spanning whole
/// resolver revolutions. nullopt when fewer than one revolution or min_samples,
/// on mismatched lengths, or when the system is singular. Throws like the class.
[[nodiscard]] std::optional<AngleErrorFit> fit_error_smooth_angle(std::span<const double> t,
                                                                  std::span<const double> theta_rd,
                                                                  const AngleFourierConfig& config);

}  // namespace resolver
