// Hwang et al. (2009) integral estimator of the amplitude imbalance alpha from
// the R/D angle alone, at constant speed.
//
// Physics: with amplitude imbalance the R/D converter reports phi with
// eps = theta - phi ~ (alpha/2) sin(2 theta)  (Hwang eq. 10, Hanselman eq. 5).
// At constant speed the true angle rises linearly, so over one resolver
// electrical revolution the ideal angle is a straight line in time and
// eps = theta_ideal - theta_rd is measurable. Hwang Fig. 4: alpha/2 is
// "Area-0 minus Area-1" of eps over the quarters of the revolution where
// sin(2 theta) is positive/negative, divided by the same areas of sin(2 theta)
// with unit amplitude. Over a whole revolution, using all four quarters:
//
//     alpha/2 = sum_i s(theta_i) eps_i / sum_i s(theta_i) sin(2 theta_i),
//     s(theta) = +1 in quarters 0 and 2, -1 in quarters 1 and 3.
//
// The sign weighting makes the estimate blind to a constant, to 1x terms
// (offsets) and to cos(2 theta) terms (quadrature, Hanselman eq. 7), whose
// quarter areas cancel.
//
// The ideal line: its slope is 2pi / (time between two crossings of the same
// R/D angle level k*2pi). Any error that is periodic in theta takes the same
// value at both crossings, so the slope is exact at constant speed; fitting a
// least-squares line instead would absorb ~19 % of the sin(2 theta) term into
// the slope (the ramp is not orthogonal to sin 2theta over one revolution).
//
// Per revolution one alpha_k is produced; the estimate is their mean, and the
// spread over revolutions gives the standard error. Revolutions whose speed
// differs from the previous one by more than `max_speed_change` are rejected
// (the method assumes constant speed) and counted.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "daemon/core/angles.h"

namespace resolver {

struct HwangIntegralConfig {
  /// Revolutions needed before the estimate is declared converged.
  int min_revolutions = 3;
  /// Largest relative change of revolution period between consecutive
  /// revolutions still treated as constant speed [-].
  double max_speed_change = 0.02;
  /// Fewest samples per resolver electrical revolution: below this the quarter
  /// sums are too coarse (at 16 samples the sign-weighted sin(2 theta) sum
  /// deviates from its integral by < 3 %, and the ratio cancels most of that).
  int min_samples_per_revolution = 16;
  /// A revolution taking longer than this is a stop, not a revolution [s].
  double max_revolution_time_s = 10.0;
  /// Largest time step between consecutive samples (and from the crossings to the
  /// first and last sample) in units of the revolution's mean sample interval; a
  /// longer step means lost samples. 2.5: at constant speed and a fixed rate the
  /// steps are 1 interval (2 at most next to a crossing); one lost sample makes 2.
  double max_gap_intervals = 2.5;
  bool operator==(const HwangIntegralConfig&) const = default;
};

/// Result of one completed resolver electrical revolution.
struct HwangRevolution {
  double alpha = 0.0;          ///< this revolution's alpha [-]
  double omega = 0.0;          ///< resolver electrical speed [rad/s] (signed)
  int samples = 0;             ///< samples in the revolution
};

/// kGap: samples missing inside the revolution (lost frames): the quarter sums
/// no longer balance and alpha_k can be off by any amount. Seen in the vcan soak
/// with kernel drops: one such revolution took the mean to -3.9e9.
enum class HwangRejection : std::uint8_t { kSpeedNotConstant, kTooFewSamples, kTooSlow, kGap };

struct HwangIntegralState {
  AngleUnwrapper unwrap;
  bool started = false;         ///< at least one sample seen
  bool have_start = false;      ///< a revolution boundary has been crossed
  std::int64_t rev_index = 0;   ///< floor(theta_unwrapped / 2pi) of the last sample
  double start_time = 0.0;      ///< [s] time of the boundary crossing that opened the revolution
  double start_level = 0.0;     ///< [rad] unwrapped angle of that boundary
  double last_t = 0.0;          ///< [s]
  double last_theta = 0.0;      ///< [rad] unwrapped
  std::vector<double> t;        ///< [s] samples of the open revolution
  std::vector<double> theta;    ///< [rad] unwrapped R/D angle of the open revolution
  std::optional<double> last_period;  ///< [s] period of the previous revolution
  // Welford accumulators over accepted revolutions.
  std::int64_t revolutions = 0;
  double mean = 0.0;
  double m2 = 0.0;
  std::int64_t samples_used = 0;
  std::int64_t rejected[4] = {0, 0, 0, 0};
};

class HwangIntegralEstimator {
 public:
  explicit HwangIntegralEstimator(const HwangIntegralConfig& config) : config_(config) {}

  /// Feeds one R/D angle sample: t [s], theta_rd [rad] (wrapped or not).
  /// Returns the revolution's result when this sample closes a revolution.
  std::optional<HwangRevolution> update(double t, double theta_rd);

  /// Mean alpha over accepted revolutions [-].
  [[nodiscard]] double alpha() const { return state_.mean; }
  /// Standard error of the mean [-]; NaN with fewer than two revolutions.
  [[nodiscard]] double alpha_stderr() const;
  /// Standard deviation of alpha over revolutions [-]; NaN with fewer than two.
  [[nodiscard]] double alpha_spread() const;
  [[nodiscard]] bool converged() const { return state_.revolutions >= config_.min_revolutions; }
  [[nodiscard]] std::int64_t revolutions() const { return state_.revolutions; }
  [[nodiscard]] std::int64_t samples_used() const { return state_.samples_used; }
  [[nodiscard]] std::int64_t rejected(HwangRejection why) const {
    return state_.rejected[static_cast<int>(why)];
  }
  [[nodiscard]] const HwangIntegralState& state() const { return state_; }
  void reset() { state_ = HwangIntegralState{}; }

 private:
  std::optional<HwangRevolution> close_revolution(double t_cross, double level);

  HwangIntegralConfig config_;
  HwangIntegralState state_;
};

/// Position error of amplitude imbalance, the compensation term (Hwang eq. 10,
/// Fig. 5): eps_hat(theta) = (alpha/2) sin(2 theta) [rad]; theta_c = theta_rd + eps_hat.
[[nodiscard]] inline double amplitude_imbalance_eps(double alpha, double theta) {
  return 0.5 * alpha * std::sin(2.0 * theta);
}

}  // namespace resolver
