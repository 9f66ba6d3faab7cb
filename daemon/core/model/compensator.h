// Compensation: the fitted Model inverted, sample by sample.
//
// The model predicts the position error eps(theta) = theta_true - theta_measured
// as a function of the TRUE angle (and speed, direction, time). The corrected
// angle solves theta_c = theta_measured + eps(theta_c): a fixed point, which
// converges because |d eps / d theta| << 1 (a few iterations reach rounding for
// errors below a degree; kIterations = 4 leaves (d eps/d theta)^4 of the error).
// Angle domain: the R/D angle with the rd prediction (every resolver-side effect:
// windings, harmonics, eccentricity and mechanical orders, mounting, delay as
// omega d, backlash by direction, the converter's loop). Signal domain: the angle
// of the raw sin/cos with the sa prediction (the envelopes' own errors; no loop).
//
// The mechanical angle a mechanical harmonic needs is the compensated resolver
// angle unwrapped over p_r, plus the offset of the resolver's cycle against the
// mechanical zero: learned from the reference while there is one (learn_reference),
// else 0 (then mechanical orders compensate only if the resolver's zero is the
// rotor's, which the run report says).
#pragma once

#include "daemon/core/angles.h"
#include "daemon/core/model/model.h"

namespace resolver {

class Compensator {
 public:
  Compensator() = default;
  explicit Compensator(Model model);
  /// A newer estimate of the same sensor: the angle tracking (unwrapping, the
  /// resolver's cycle learned from the reference, the direction) goes on.
  void replace_model(Model model);

  /// The corrected angle [rad, wrapped] for a measured angle `theta_meas` [rad] at
  /// time t [s], speed omega [rad/s, resolver electrical], acceleration accel
  /// [rad/s^2]; `sincos` = the measured angle is atan2 of the envelopes (signal
  /// domain). Cannot fail.
  [[nodiscard]] double correct(double theta_meas, double t, double omega, double accel, bool sincos);
  /// eps_hat of the last correct() [rad].
  [[nodiscard]] double last_eps() const { return last_eps_; }
  /// A reference sample: the mechanical angle [rad, wrapped] at the last corrected angle.
  void learn_reference(double theta_m_ref);

  [[nodiscard]] const Model& model() const { return model_; }
  [[nodiscard]] bool active() const { return active_; }

 private:
  static constexpr int kIterations = 4;
  Model model_;
  bool active_ = false;
  AngleUnwrapper unwrap_;
  double cycle_offset_ = 0.0;  ///< [rad, mechanical] mechanical angle minus unwrapped angle / p_r
  bool cycle_known_ = false;
  double last_eps_ = 0.0;
  double last_theta_c_cont_ = 0.0;
  double direction_ = 1.0;
};

}  // namespace resolver
