// Effect: the dynamics of a type-II tracking R/D converter.
//
// The converter (Hanselman II.A and Fig. 1, Hwang Fig. 2) multiplies the sin
// envelope by cos(phi) and the cos envelope by sin(phi), takes the difference
//   e = s cos(phi) - c sin(phi)          (= sin(theta - phi) for ideal envelopes,
//                                         Hanselman eq. 3, Hwang eq. 4)
// and drives it to zero with a type-II servo (two integrators plus a zero):
//   d(phi)/dt   = w + 2 zeta omega_n e
//   d(w)/dt     = omega_n^2 e
// Linearised (e ~= theta - phi) the closed loop is
//   Phi(s)/Theta(s) = H(s) = (2 zeta omega_n s + omega_n^2) / (s^2 + 2 zeta omega_n s + omega_n^2),
// so a constant speed is tracked with zero error (type II), a constant
// acceleration a [rad/s^2] lags by a / omega_n^2, and error harmonics of the
// envelopes at speed-dependent frequencies are filtered by H (docs/ARCHITECTURE.md §7: the
// ripple's amplitude and phase change with speed).
//
// Integration: classical RK4 with the envelopes evaluated at the true angle of
// each stage time, so the true angle advances continuously inside a control
// sample period. The loop's poles have |lambda| = omega_n; RK4 is stable for
// |lambda h| < ~2.8 and its one-step error is ~(lambda h)^5 / 120. We keep
// omega_n h <= kTrackingLoopMaxOmegaNStep = 0.05: the per-step error is ~3e-9
// relative, i.e. the integration is far below any quantization or noise level.
//
// omega_n == 0 selects the ideal, infinitely fast converter: phi equals the
// static equilibrium atan2(s, c) at every instant.
//
// The loop's parameters are the effect's one list (kTrackingLoopParams): the
// simulated converter, the chain's ConverterSpec and the fit's BasisTransform hold
// a TrackingLoopParams, tracking_loop_fit.h's estimate gives one, all read by name.
#pragma once

#include <array>
#include <cmath>
#include <complex>

#include "daemon/core/angles.h"
#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kTrackingLoopParams{
    ParamInfo{.name = "omega_n", .unit = "[rad/s]",
              .description = "closed-loop natural frequency (0 = ideal converter)", .min = 0.0, .max = 1e6,
              .neutral = 0.0, .nonlinear = true, .scale = FitScale::kInverseSquare},
    ParamInfo{.name = "zeta", .unit = "[1]", .description = "closed-loop damping ratio", .min = 0.01, .max = 10.0,
              .neutral = 0.7, .nonlinear = true, .default_fit = false},
};
/// A loop: omega_n [rad/s] (0 = ideal converter, >= 0) and zeta [1] (> 0), by name.
using TrackingLoopParams = ParamSet<kTrackingLoopParams>;

/// Largest omega_n * h of one RK4 substep [1] (see the header comment).
inline constexpr double kTrackingLoopMaxOmegaNStep = 0.05;

/// True when the loop filters (omega_n > 0); omega_n = 0 is the ideal converter
/// whatever zeta is (the effect's rule, not ParamSet::active's).
[[nodiscard]] constexpr bool tracking_loop_active(const TrackingLoopParams& p) { return p["omega_n"] > 0.0; }

struct TrackingLoopState {
  double phi = 0.0;    ///< [rad] converter angle, continuous (not wrapped)
  double omega = 0.0;  ///< [rad/s] converter velocity (the second integrator)
};

/// Number of RK4 substeps advance() takes over `duration` [s]. At least 1.
[[nodiscard]] int tracking_loop_substeps(const TrackingLoopParams& config, double duration);

class TrackingLoop {
 public:
  explicit TrackingLoop(const TrackingLoopParams& config) : config_(config) {}

  /// Sets the state, e.g. to a converged loop: phi = true angle, omega = true speed.
  void reset(const TrackingLoopState& state) { state_ = state; }

  /// Advances the loop from time t0 to t0 + duration [s]. `envelope_at(t)` must
  /// return the envelopes (SinCos) seen by the converter at time t [s]; it is
  /// evaluated at t0, the substep mid-points and ends.
  template <typename EnvelopeAt>
  void advance(EnvelopeAt&& envelope_at, double t0, double duration) {
    if (!tracking_loop_active(config_)) {
      // Ideal converter: follow the static angle, keep phi continuous.
      const double target = static_rd_angle(envelope_at(t0 + duration));
      const double step = wrap_pi(target - state_.phi);
      state_.omega = duration > 0.0 ? step / duration : 0.0;
      state_.phi += step;
      return;
    }
    const int n = tracking_loop_substeps(config_, duration);
    const double h = duration / n;
    SinCos at_start = envelope_at(t0);
    for (int i = 0; i < n; ++i) {
      const double t = t0 + h * i;
      const SinCos at_mid = envelope_at(t + 0.5 * h);
      const SinCos at_end = envelope_at(t + h);
      rk4_step(at_start, at_mid, at_end, h);
      at_start = at_end;
    }
  }

  [[nodiscard]] const TrackingLoopState& state() const { return state_; }
  [[nodiscard]] const TrackingLoopParams& config() const { return config_; }
  /// Converter angle wrapped to [0, 2pi) [rad].
  [[nodiscard]] double angle() const { return wrap_2pi(state_.phi); }

 private:
  void rk4_step(const SinCos& at_start, const SinCos& at_mid, const SinCos& at_end, double h);

  TrackingLoopParams config_;
  TrackingLoopState state_;
};

/// H(j omega) of the linearised closed loop [1] at angular frequency omega [rad/s],
/// signed (the negative-frequency response is the conjugate); 1 for the ideal converter.
[[nodiscard]] std::complex<double> tracking_loop_response(const TrackingLoopParams& config, double omega);
/// The linearised loop's response to a harmonic whose frequency omega [rad/s] changes at
/// `omega_rate` [rad/s^2] (the speed ramps): H(j omega) - (j/2) omega_rate H''(omega), with
/// H'' the second derivative in the frequency. Why: the filter's output is the integral of
/// its impulse response over the input's recent past, whose phase is
/// Phi(t - tau) = Phi - omega tau + omega_rate tau^2 / 2; to first order in the rate that adds
/// (j/2) omega_rate times the integral of tau^2 h(tau) e^{-j omega tau}, which is -H''. Without
/// it a 15 % gain error's 2 theta ripple on a 0-1500 r/min ramp in 1.5 s is off by ~5e-6 rad
/// (loop_correction_test); the rest is second order in the rate.
[[nodiscard]] std::complex<double> tracking_loop_response(const TrackingLoopParams& config, double omega,
                                                          double omega_rate);
/// The linearised closed-loop gain |H(j omega)| of the loop at angular frequency omega [rad/s].
[[nodiscard]] double tracking_loop_gain(const TrackingLoopParams& config, double omega);
/// The linearised closed-loop phase arg H(j omega) [rad].
[[nodiscard]] double tracking_loop_phase(const TrackingLoopParams& config, double omega);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& tracking_loop_effect();

}  // namespace resolver
