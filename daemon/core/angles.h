// Angle conventions of the whole project (docs/ARCHITECTURE.md §3), written down once.
//
//   theta_m   mechanical rotor angle [rad]
//   theta     resolver electrical angle = p_r * theta_m [rad]  (p_r: resolver pole pairs)
//   theta_e   motor electrical angle    = p   * theta_m [rad]  (p: motor pole pairs)
//             so theta_e = (p / p_r) * theta  (Hwang eq. 19)
//   eps       position error = theta_true - theta_measured (Hanselman's sign);
//             a compensated angle is theta_measured + eps_hat(theta_measured).
//
// Angles are radians everywhere inside; degrees/arcmin only at the edges (CLI, report).
// Wrapped angles live in [0, 2pi); angle differences in [-pi, pi).
#pragma once

#include <cmath>
#include <numbers>

namespace resolver {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Wraps any angle [rad] into [0, 2pi).
[[nodiscard]] inline double wrap_2pi(double a) {
  double w = std::fmod(a, kTwoPi);
  if (w < 0.0) w += kTwoPi;
  // fmod can return exactly 2pi after the += for tiny negative inputs.
  return w >= kTwoPi ? 0.0 : w;
}

/// Wraps an angle difference [rad] into [-pi, pi).
[[nodiscard]] inline double wrap_pi(double a) { return wrap_2pi(a + kPi) - kPi; }

/// Unwraps a stream of wrapped angles into a continuous one.
/// State is the last wrapped input and the running continuous output.
struct AngleUnwrapper {
  bool started = false;
  double last_wrapped = 0.0;
  double continuous = 0.0;

  /// Returns the continuous angle [rad] for a new wrapped sample [rad].
  double update(double wrapped) {
    if (!started) {
      started = true;
      last_wrapped = wrapped;
      continuous = wrapped;
      return continuous;
    }
    continuous += wrap_pi(wrapped - last_wrapped);
    last_wrapped = wrapped;
    return continuous;
  }
};

[[nodiscard]] constexpr double rad_to_deg(double r) { return r * 180.0 / kPi; }
[[nodiscard]] constexpr double rad_to_arcmin(double r) { return r * 10800.0 / kPi; }

}  // namespace resolver
