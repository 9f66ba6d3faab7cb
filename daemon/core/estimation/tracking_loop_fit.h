// Identification of the R/D converter's tracking loop (omega_n, zeta) from how the
// 2x ripple of the position error changes with speed (docs/ARCHITECTURE.md §7,
// tracking_loop: the ripple's amplitude and phase change with speed).
//
// Physics. The sin/cos imperfections give a static error eps_s(theta): the angle
// an infinitely fast converter would read is theta_app = theta - eps_s(theta)
// (amplitude imbalance: eps_s ~ (alpha/2) sin 2theta, Hanselman eq. 5, Hwang eq. 10).
// Linearised about that equilibrium the converter's error signal is
//   E = s cos(phi) - c sin(phi) ~= g (theta_app - phi)        (Hanselman eq. 3)
// so the type-II loop (daemon/core/effects/tracking_loop.h) outputs
//   phi = H(s) theta_app,  H(s) = (2 zeta wn s + wn^2) / (s^2 + 2 zeta wn s + wn^2),
// and the measured error is
//   eps = theta - phi = (1 - H) theta + H eps_s.
// (1 - H) theta vanishes in steady state at constant speed (type II), so every
// harmonic of eps_s is simply filtered by the CLOSED loop H at its own frequency:
// at resolver electrical speed omega_e [rad/s] the n-th harmonic, which runs at
// n omega_e, comes out as H(j n omega_e) times its static value. Checked against
// the bench simulator (RK4 loop on the nonlinear error signal) in
// tests/unit/estimation/test_tracking_loop_fit.cpp.
//
// Complex coefficients. We write a harmonic as eps_n = a sin(n theta) + b cos(n theta)
// = Im{C e^{j n theta}} with C = a + j b, theta the TRUE (reference) angle. A real
// LTI filter multiplies C by its complex gain, so at speed omega_e (signed: the
// negative-frequency gain is the conjugate)
//   C(omega_e) = C_static H(j n omega_e; omega_n, zeta)                       (1)
// and the 2x ripple's amplitude |C| and phase arg C follow |H| and arg H. C_static
// comes from a signal-domain fit which does not see the loop (sincos_least_squares.h:
// for alpha alone a = alpha/(2 + alpha), b = 0), from a low-speed observation
// (|H - 1| < 1e-3 below n omega_e < omega_n/30), or is fitted jointly (below).
//
// Second-order effect: g above is the loop gain at the actual signal amplitudes,
// g = 1 + alpha cos^2 theta for a cos channel of gain 1 + alpha, whose mean 1 + alpha/2
// scales the loop's gains, so the loop identified is the effective one:
// omega_n,eff = omega_n sqrt(1 + alpha/2), zeta_eff = zeta sqrt(1 + alpha/2)
// (+0.25 % each for alpha = 0.01). That is the loop that filters the ripple on this
// bench, i.e. the one the model needs; a datasheet omega_n is quoted at nominal amplitude.
//
// Estimation. Weighted nonlinear least squares on (1): per observation k the
// residuals Re and Im of (m_k - C_static H_k) / sigma_k. Parameters ln omega_n,
// ln zeta (positive by construction), and optionally Re/Im C_static. Start: the
// best point of a log grid (omega_n over [0.05, 20] x the observed n|omega_e| range,
// zeta over [0.05, 5]), C_static solved linearly at each grid point when it is
// fitted; then Levenberg-Marquardt with the analytic Jacobian
//   dH/d omega_n = (2 zeta s + 2 omega_n) s^2 / D^2,  dH/d zeta = 2 omega_n s^3 / D^2,
//   D = s^2 + 2 zeta omega_n s + omega_n^2,  s = j n omega_e.
// Covariance: (J^T J)^-1 in the weighted residuals, multiplied by the reduced
// chi^2 when that exceeds 1 (the observations' std errors then understate the
// scatter: unmodelled second-order terms, quantization dither), then mapped to
// (omega_n, zeta) by the delta method (d omega_n = omega_n d ln omega_n).
//
// Ripple extraction (measure_ripple, ripple_observations): eps = wrap_pi(theta_ref -
// theta_rd) is fitted by ordinary least squares on [1, sin k theta_ref, cos k theta_ref,
// k = 1..max_order] over whole revolutions of a constant-speed stretch; the n-th pair
// gives C, its standard error is the residual rms times sqrt of the diagonal of
// (X^T X)^-1 (the mean of the sin and cos entries: equal over whole revolutions);
// omega_e is the LS slope of the unwrapped theta_ref against t. Avoid speeds at
// which a revolution is a whole number of samples (e.g. 5000 r/min, p_r = 3, 20 kHz:
// 80 samples): the R/D quantization error then repeats every revolution and biases
// the coefficient (2e-5 rad at 16 bits) instead of averaging out.
//
// Nothing here allocates more than O(samples) or does I/O; nothing throws except
// on invalid configuration (std::invalid_argument naming the field).
#pragma once

#include <complex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "daemon/core/effects/tracking_loop.h"

namespace resolver {

/// The n-th harmonic of eps measured at one speed.
struct RippleObservation {
  double omega_e = 0.0;              ///< [rad/s] resolver electrical speed (signed)
  std::complex<double> measured;     ///< [rad] a + j b of eps = a sin(n theta) + b cos(n theta)
  double std_error = 0.0;            ///< [rad] standard error of Re and of Im (each); > 0
  double revolutions = 0.0;          ///< resolver electrical revolutions used (0 if not from measure_ripple)
  double t_begin = 0.0, t_end = 0.0; ///< [s] time span used
  double residual_rms = 0.0;         ///< [rad] rms residual of the harmonic fit
};

/// The static harmonic C_static of (1).
struct StaticRipple {
  std::complex<double> value;  ///< [rad] a + j b (initial guess when free)
  /// [rad] std error of Re and of Im: 0 = exact (not fitted); finite > 0 = a prior
  /// (fitted, pulled towards value); +infinity = free (fitted from the observations
  /// alone: they must then include low speeds, n |omega_e| << omega_n).
  double std_error = 0.0;
};

struct TrackingLoopFitConfig {
  int order = 2;             ///< harmonic order n the observations carry (1..16)
  int max_iterations = 100;  ///< Levenberg-Marquardt iterations (>= 1)
  /// ok = false when the relative std error of omega_n exceeds this (the speeds do
  /// not reach omega_n: |H| ~ 1 everywhere and the loop is not identifiable).
  double max_relative_stderr = 0.5;
};

struct TrackingLoopEstimate {
  double omega_n = 0.0;         ///< [rad/s]
  double zeta = 0.0;            ///< [1]
  double omega_n_stderr = 0.0;  ///< [rad/s]
  double zeta_stderr = 0.0;     ///< [1]
  std::complex<double> static_coefficient;  ///< [rad] C_static (given or fitted)
  double static_stderr = 0.0;               ///< [rad] its std error per component (0 when given exactly)
  /// Covariance of (omega_n, zeta, Re C_static, Im C_static) [rad/s, 1, rad, rad];
  /// the C rows are zero when C_static was given exactly. Already scaled (header).
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  int order = 2;                ///< harmonic order fitted
  double chi2 = 0.0;            ///< sum of squared weighted residuals
  int dof = 0;                  ///< residuals minus parameters
  double residual = 0.0;        ///< reduced chi^2 = chi2 / dof (1 when the std errors are right)
  int iterations = 0;
  bool ok = false;              ///< converged, dof >= 1, identifiable (see config)
  std::string message;          ///< why not ok (empty when ok)

  [[nodiscard]] TrackingLoopParams loop() const { return {{"omega_n", omega_n}, {"zeta", zeta}}; }
};

/// Fits (omega_n, zeta) to observations of one harmonic order. Never throws on
/// data: bad data give ok = false and a message (fewer than 2 observations, a
/// non-finite value or std_error <= 0, a singular problem). Throws
/// std::invalid_argument on an invalid config.
[[nodiscard]] TrackingLoopEstimate fit_tracking_loop(const StaticRipple& static_ripple,
                                                     std::span<const RippleObservation> observations,
                                                     const TrackingLoopFitConfig& config = {});
/// Same, with C_static known exactly.
[[nodiscard]] TrackingLoopEstimate fit_tracking_loop(std::complex<double> static_coefficient,
                                                     std::span<const RippleObservation> observations,
                                                     const TrackingLoopFitConfig& config = {});

/// The model's harmonic at speed omega_e [rad/s] with its std error per component
/// (delta method through the estimate's covariance).
struct RipplePrediction {
  std::complex<double> value;  ///< [rad] C_static H(j n omega_e)
  double std_re = 0.0;         ///< [rad]
  double std_im = 0.0;         ///< [rad]
};
[[nodiscard]] RipplePrediction predict_ripple(const TrackingLoopEstimate& estimate, double omega_e);

/// The predicted ripple part of eps = theta - theta_rd [rad] at true resolver angle
/// theta [rad] and speed omega_e [rad/s] (steady state): Im{C(omega_e) e^{j n theta}}.
/// The R/D angle is then theta_rd ~= theta - eps (plus the other harmonics).
[[nodiscard]] double predict_ripple_error(const TrackingLoopEstimate& estimate, double theta, double omega_e);

struct RippleBinConfig {
  int order = 2;       ///< harmonic reported (1..max_order)
  int max_order = 4;   ///< harmonics 1..max_order fitted jointly (plus a constant)
  /// Relative speed change [1] allowed between the revolutions of one bin,
  /// against the bin's first revolution.
  double speed_tolerance = 0.002;
  /// [s] dropped at the start of each constant-speed stretch (loop transient after a
  /// speed change: a few 1/(zeta omega_n)).
  double settle_s = 0.05;
  int min_revolutions = 4;  ///< fewer whole revolutions: no observation
  int max_revolutions = 0;  ///< > 0: longer stretches are split into bins of this many
};

/// The harmonic of eps over one constant-speed stretch of samples t [s],
/// theta_ref, theta_rd [rad] (resolver electrical; wrapped or continuous). Uses the
/// longest prefix spanning whole revolutions. nullopt on mismatched lengths, fewer
/// than one revolution or than 4 max_order + 2 samples, or a singular system.
/// Throws std::invalid_argument on an invalid config.
[[nodiscard]] std::optional<RippleObservation> measure_ripple(std::span<const double> t,
                                                              std::span<const double> theta_ref,
                                                              std::span<const double> theta_rd,
                                                              const RippleBinConfig& config = {});

/// Splits a record into constant-speed bins (whole revolutions whose speeds agree
/// within speed_tolerance, minus settle_s, at least min_revolutions) and measures
/// each. Ramps give no bins unless slow enough to pass the tolerance. Empty on
/// mismatched lengths. Throws std::invalid_argument on an invalid config.
[[nodiscard]] std::vector<RippleObservation> ripple_observations(std::span<const double> t,
                                                                 std::span<const double> theta_ref,
                                                                 std::span<const double> theta_rd,
                                                                 const RippleBinConfig& config = {});

}  // namespace resolver
