// Compensation in the signal domain: correct the sin/cos envelopes with a
// SinCosFit before taking the angle (docs/ARCHITECTURE.md §5), Hanselman's sum/difference for
// quadrature (eqs. 11-12), and a software type-II tracking observer.
//
// Inverse of the catalog model (sincos_least_squares.h), in steps:
//   s1 = s/A - o_s                               = sin t + sum K_n sin n t
//   c1 = (c/A - o_c) / (1 + alpha)               = cos(t + beta) + sum K_n cos n t
//   harmonics: t0 = first-pass angle; s1 -= sum K_n sin(n t0), c1 -= sum K_n cos(n t0)
//              (one fixed-point step: the residual is O(K_n * angle error), second order)
//   quadrature: cos(t + beta) = cos t cos beta - sin t sin beta, so
//              cos t = (c1 + s1 sin beta) / cos beta                   (orthogonalisation)
//   theta = atan2(s1, cos t).
// Noise: every step is linear with gains 1/A, 1/(A(1+alpha)), 1/cos beta, so the
// corrected angle keeps the floor sigma/A of the raw atan2 to O(alpha, beta).
//
// Sum/difference (Hanselman eq. 11-12), with s1 = sin t and c1 = cos(t + beta):
//   V_s^ = s1 + c1 =  2 cos(sigma) sin(t + sigma)
//   V_c^ = s1 - c1 = -2 sin(sigma) cos(t + sigma),    sigma = beta/2 + pi/4,
// so t = atan2(V_s^ / (2 cos sigma), V_c^ / (-2 sin sigma)) - sigma: the
// quadrature error is gone; the inverting gain stage and the subtraction of
// sigma are what Hanselman leaves to "appropriate logic".
#pragma once

#include <vector>

#include "daemon/core/effects/sin_cos.h"
#include "daemon/core/estimation/sincos_least_squares.h"

namespace resolver {

/// The parameters the correction needs (plain values, from a SinCosFit or set by hand).
struct SinCosCorrection {
  double amplitude = 1.0;  ///< [signal units] A
  double alpha = 0.0;      ///< [1]
  double beta = 0.0;       ///< [rad]
  double o_s = 0.0;        ///< [fraction of A]
  double o_c = 0.0;        ///< [fraction of A]
  std::vector<int> orders;     ///< harmonic orders n of k
  std::vector<double> k;       ///< [fraction of A] K_n

  [[nodiscard]] static SinCosCorrection from_fit(const SinCosFit& fit);
};

/// Corrected unit envelopes {sin t, cos t} from raw (s, c) [signal units]. Cannot fail.
[[nodiscard]] SinCos correct_sincos(const SinCosCorrection& corr, double s, double c);

/// atan2 of the corrected envelopes [rad], wrapped to [0, 2pi).
[[nodiscard]] double corrected_angle(const SinCosCorrection& corr, double s, double c);

/// Hanselman's sum/difference angle [rad] in [0, 2pi): offsets and gain removed as
/// above, quadrature by eqs. 11-12 instead of orthogonalisation (harmonics not removed).
[[nodiscard]] double sum_difference_angle(const SinCosCorrection& corr, double s, double c);

struct TrackingObserverConfig {
  double omega_n = 500.0;     ///< [rad/s] closed-loop natural frequency
  double zeta = 0.7;          ///< [1] damping ratio, > 0
  double sample_period = 5e-4;  ///< [s] time between updates
};

struct TrackingObserverState {
  bool started = false;
  double phi = 0.0;    ///< [rad] angle estimate, continuous
  double omega = 0.0;  ///< [rad/s] speed estimate
};

/// Software type-II tracking loop on (corrected) envelopes, as a discrete
/// predictor-corrector (two integrators, zero steady-state error at constant speed):
///   predict   phi- = phi + h omega
///   error     e = s cos(phi-) - c sin(phi-)    (= sin(theta - phi-), Hanselman eq. 3)
///   correct   phi = phi- + g e,   omega = omega + (k / h) e
/// Error dynamics on (theta - phi, h (omega_true - omega)) have the characteristic
/// polynomial z^2 - (2 - g - k) z + (1 - g); placing its roots at the continuous
/// loop's poles mapped by z = exp(s h), s = -zeta omega_n +- j omega_n sqrt(1 - zeta^2):
///   g = 1 - exp(-2 zeta omega_n h)
///   k = 1 + exp(-2 zeta omega_n h) - 2 exp(-zeta omega_n h) cos(omega_n h sqrt(1 - zeta^2))
///   (cosh for zeta > 1). For omega_n h << 1, k ~ (omega_n h)^2: the continuous
///   loop of daemon/core/effects/tracking_loop.h. Under a constant acceleration a
///   the angle lags by a h^2 (1 - g) / k ~ a / omega_n^2.
class TrackingObserver {
 public:
  /// Throws std::invalid_argument when omega_n <= 0, zeta <= 0 or sample_period <= 0.
  explicit TrackingObserver(const TrackingObserverConfig& config);

  /// One sample of unit envelopes; returns the angle [rad] wrapped to [0, 2pi).
  /// The first sample initialises phi = atan2(s, c), omega = 0.
  double update(const SinCos& sc);

  [[nodiscard]] double angle() const { return wrap_2pi(state_.phi); }
  [[nodiscard]] double speed() const { return state_.omega; }
  [[nodiscard]] double gain_angle() const { return g_; }
  [[nodiscard]] double gain_speed() const { return k_; }
  [[nodiscard]] const TrackingObserverState& state() const { return state_; }
  void reset(const TrackingObserverState& state = {}) { state_ = state; }

 private:
  TrackingObserverConfig config_;
  TrackingObserverState state_;
  double g_ = 0.0;
  double k_ = 0.0;
};

}  // namespace resolver
