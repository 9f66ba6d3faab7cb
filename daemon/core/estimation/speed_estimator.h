// Speed from successive angle samples, smoothed by a first-order low-pass.
// Pure: the caller passes the sample time.
#pragma once

#include "daemon/core/angles.h"

namespace resolver {

struct SpeedEstimatorConfig {
  /// Low-pass time constant [s]. 20 ms keeps R/D quantization noise
  /// (1 LSB / sample period) well below the speed while following steps.
  double time_constant_s = 0.02;
};

class SpeedEstimator {
 public:
  explicit SpeedEstimator(SpeedEstimatorConfig config = {}) : config_(config) {}

  /// t [s], theta [rad] (wrapped or continuous). Returns the speed [rad/s].
  double update(double t, double theta) {
    const double cont = unwrap_.update(theta);
    if (!started_) {
      started_ = true;
    } else if (t > last_t_) {
      const double dt = t - last_t_;
      const double raw = (cont - last_theta_) / dt;
      const double k = dt / (config_.time_constant_s + dt);
      speed_ = primed_ ? speed_ + k * (raw - speed_) : raw;
      primed_ = true;
    }
    last_t_ = t;
    last_theta_ = cont;
    return speed_;
  }
  [[nodiscard]] double speed() const { return speed_; }

 private:
  SpeedEstimatorConfig config_;
  AngleUnwrapper unwrap_;
  bool started_ = false;
  bool primed_ = false;
  double last_t_ = 0.0;
  double last_theta_ = 0.0;
  double speed_ = 0.0;
};

}  // namespace resolver
