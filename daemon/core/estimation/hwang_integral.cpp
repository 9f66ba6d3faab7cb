#include "daemon/core/estimation/hwang_integral.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace resolver {

std::optional<HwangRevolution> HwangIntegralEstimator::update(double t, double theta_rd) {
  HwangIntegralState& s = state_;
  const double theta = s.unwrap.update(theta_rd);
  const auto index = static_cast<std::int64_t>(std::floor(theta / kTwoPi));
  std::optional<HwangRevolution> result;

  if (!s.started) {
    // Very first sample: remember it, then wait for the first boundary crossing.
    s.started = true;
    s.rev_index = index;
    s.last_t = t;
    s.last_theta = theta;
    return std::nullopt;
  }

  // Crossed the level between the previous sample and this one. Moving up the
  // level is index*2pi, moving down it is (index+1)*2pi. Noise at a standstill
  // that jitters back and forth across the level it started from is not a
  // revolution: a revolution ends only at a level 2pi away from its start.
  const double crossed = (index > s.rev_index ? static_cast<double>(index) : static_cast<double>(index + 1)) * kTwoPi;
  if (index != s.rev_index && s.have_start && crossed == s.start_level) {
    s.rev_index = index;
  } else if (index != s.rev_index) {
    const double level = crossed;
    const double dtheta = theta - s.last_theta;
    const double frac = dtheta != 0.0 ? (level - s.last_theta) / dtheta : 0.0;
    const double t_cross = s.last_t + frac * (t - s.last_t);
    if (s.have_start) result = close_revolution(t_cross, level);
    s.have_start = true;
    s.start_time = t_cross;
    s.start_level = level;
    s.t.clear();
    s.theta.clear();
    s.rev_index = index;
  }
  if (s.have_start) {
    s.t.push_back(t);
    s.theta.push_back(theta);
    if (t - s.start_time > config_.max_revolution_time_s) {
      ++s.rejected[static_cast<int>(HwangRejection::kTooSlow)];
      s.have_start = false;  // wait for the next boundary
      s.last_period.reset();
      s.t.clear();
      s.theta.clear();
    }
  }
  s.last_t = t;
  s.last_theta = theta;
  return result;
}

std::optional<HwangRevolution> HwangIntegralEstimator::close_revolution(double t_cross, double level) {
  HwangIntegralState& s = state_;
  const double period = t_cross - s.start_time;
  const auto n = static_cast<int>(s.t.size());
  if (period <= 0.0) return std::nullopt;
  const std::optional<double> previous = s.last_period;
  s.last_period = period;
  if (n < config_.min_samples_per_revolution) {
    ++s.rejected[static_cast<int>(HwangRejection::kTooFewSamples)];
    return std::nullopt;
  }
  if (previous && std::abs(period - *previous) > config_.max_speed_change * *previous) {
    ++s.rejected[static_cast<int>(HwangRejection::kSpeedNotConstant)];
    return std::nullopt;
  }
  double max_step = std::max(s.t.front() - s.start_time, t_cross - s.t.back());
  for (std::size_t i = 1; i < s.t.size(); ++i) max_step = std::max(max_step, s.t[i] - s.t[i - 1]);
  if (max_step > config_.max_gap_intervals * period / static_cast<double>(n)) {
    ++s.rejected[static_cast<int>(HwangRejection::kGap)];
    return std::nullopt;
  }
  // Ideal angle: straight line through the two crossings of the same R/D level.
  const double omega = (level - s.start_level) / period;
  double num = 0.0;
  double den = 0.0;
  for (int i = 0; i < n; ++i) {
    const double ideal = s.start_level + omega * (s.t[static_cast<std::size_t>(i)] - s.start_time);
    const double eps = ideal - s.theta[static_cast<std::size_t>(i)];
    const double w = wrap_2pi(ideal);
    // Quarter 0 and 2 (sin 2theta >= 0) weigh +1, quarters 1 and 3 weigh -1.
    const int quarter = static_cast<int>(w / (0.5 * kPi)) & 3;
    const double sign = (quarter % 2 == 0) ? 1.0 : -1.0;
    num += sign * eps;
    den += sign * std::sin(2.0 * ideal);
  }
  if (den == 0.0) return std::nullopt;
  HwangRevolution rev;
  rev.alpha = 2.0 * num / den;
  rev.omega = omega;
  rev.samples = n;

  // Welford update of the mean and variance over revolutions.
  ++s.revolutions;
  const double delta = rev.alpha - s.mean;
  s.mean += delta / static_cast<double>(s.revolutions);
  s.m2 += delta * (rev.alpha - s.mean);
  s.samples_used += n;
  return rev;
}

double HwangIntegralEstimator::alpha_spread() const {
  if (state_.revolutions < 2) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(state_.m2 / static_cast<double>(state_.revolutions - 1));
}

double HwangIntegralEstimator::alpha_stderr() const {
  if (state_.revolutions < 2) return std::numeric_limits<double>::quiet_NaN();
  return alpha_spread() / std::sqrt(static_cast<double>(state_.revolutions));
}

}  // namespace resolver
