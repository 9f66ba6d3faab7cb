#include "daemon/core/discovery/motion.h"

#include <algorithm>
#include <cmath>

namespace resolver {

namespace {
constexpr int kHalfWindow = 5;            // samples each side of the speed fit
constexpr double kGapPeriods = 3.0;       // a longer step in time ends a run
constexpr double kStopNoiseMultiple = 3.0;
constexpr double kMoveNoiseMultiple = 6.0;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}
}  // namespace

double second_difference_sigma(std::span<const double> values) {
  if (values.size() < 3) return 0.0;
  std::vector<double> d;
  d.reserve(values.size());
  double mean_abs = 0.0;
  for (std::size_t i = 1; i + 1 < values.size(); ++i) {
    const double x = std::abs(values[i + 1] - 2.0 * values[i] + values[i - 1]);
    d.push_back(x);
    mean_abs += x;
  }
  mean_abs /= static_cast<double>(d.size());
  // MAD (1.4826 for Gaussian); a quantized, slow signal has a zero MAD, so the mean
  // absolute difference (sqrt(pi/2) for Gaussian) bounds it from below.
  const double mad = 1.4826 * median(d);
  const double mean_based = 1.2533 * mean_abs;
  return std::max(mad, 0.5 * mean_based) / std::sqrt(6.0);
}

std::vector<MotionSample> analyse_motion(std::span<const double> t, std::span<const double> angle,
                                         MotionSummary& summary, double initial_direction) {
  const std::size_t n = t.size();
  std::vector<MotionSample> out(n);
  summary = MotionSummary{};
  summary.samples = static_cast<std::int64_t>(n);
  if (n < 3) {
    summary.standstill = static_cast<std::int64_t>(n);
    return out;
  }
  summary.span_s = t.back() - t.front();
  std::vector<double> dts;
  dts.reserve(n);
  for (std::size_t i = 1; i < n; ++i) dts.push_back(t[i] - t[i - 1]);
  const double dt = std::max(median(dts), 1e-12);
  // Runs of time-contiguous samples.
  std::vector<std::size_t> run_start(n), run_end(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i + 1;
    while (j < n && t[j] - t[j - 1] <= kGapPeriods * dt) ++j;
    for (std::size_t k = i; k < j; ++k) {
      run_start[k] = i;
      run_end[k] = j;
    }
    i = j;
  }
  // Local quadratic fit: angle(t) ~ a + b (t - t_i) + c (t - t_i)^2 over the window.
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = std::max<std::size_t>(run_start[i], i >= kHalfWindow ? i - kHalfWindow : 0);
    const std::size_t b = std::min<std::size_t>(run_end[i], i + kHalfWindow + 1);
    if (b - a < 3) continue;
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, y0 = 0, y1 = 0, y2 = 0;
    for (std::size_t k = a; k < b; ++k) {
      const double x = t[k] - t[i], y = angle[k] - angle[i];
      const double x2 = x * x;
      s0 += 1;
      s1 += x;
      s2 += x2;
      s3 += x2 * x;
      s4 += x2 * x2;
      y0 += y;
      y1 += x * y;
      y2 += x2 * y;
    }
    // Solve the 3x3 normal equations by Cramer's rule (well conditioned: x scaled by dt).
    const double det = s0 * (s2 * s4 - s3 * s3) - s1 * (s1 * s4 - s3 * s2) + s2 * (s1 * s3 - s2 * s2);
    if (std::abs(det) < 1e-300) continue;
    const double db = s0 * (y1 * s4 - s3 * y2) - y0 * (s1 * s4 - s3 * s2) + s2 * (s1 * y2 - y1 * s2);
    const double dc = s0 * (s2 * y2 - y1 * s3) - s1 * (s1 * y2 - y1 * s2) + y0 * (s1 * s3 - s2 * s2);
    out[i].omega = db / det;
    out[i].accel = 2.0 * dc / det;
  }
  summary.angle_noise = second_difference_sigma(angle);
  const double window = 2.0 * kHalfWindow * dt;
  const double stop = kStopNoiseMultiple * summary.angle_noise;
  const double move = kMoveNoiseMultiple * summary.angle_noise;
  bool moving = false;
  double direction = initial_direction;  // a reversal at a chunk's start counts, as in the whole log
  bool have_min_max = false;
  for (std::size_t i = 0; i < n; ++i) {
    const double travel = std::abs(out[i].omega) * window;
    if (moving && travel < stop) moving = false;
    else if (!moving && travel > move) moving = true;
    out[i].moving = moving;
    if (moving) {
      const double dir = out[i].omega < 0.0 ? -1.0 : 1.0;
      if (direction != 0.0 && dir != direction) ++summary.reversals;
      direction = dir;
    }
  }
  // The direction before the first motion is the one held before the first sample, or
  // else the first motion's.
  double held = initial_direction != 0.0 ? initial_direction : 1.0;
  for (std::size_t i = 0; i < n && initial_direction == 0.0; ++i) {
    if (out[i].moving) {
      held = out[i].omega < 0.0 ? -1.0 : 1.0;
      break;
    }
  }
  bool was_moving = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (out[i].moving) held = out[i].omega < 0.0 ? -1.0 : 1.0;
    out[i].direction = held;
    if (out[i].moving) {
      ++summary.moving;
      (held > 0.0 ? summary.forward : summary.backward) += 1;
      if (i > 0 && out[i - 1].moving) summary.travelled += std::abs(angle[i] - angle[i - 1]);
      if (!have_min_max) {
        summary.omega_min = summary.omega_max = out[i].omega;
        have_min_max = true;
      }
      summary.omega_min = std::min(summary.omega_min, out[i].omega);
      summary.omega_max = std::max(summary.omega_max, out[i].omega);
    } else {
      ++summary.standstill;
      if (was_moving) ++summary.standstills;
    }
    was_moving = out[i].moving;
  }
  return out;
}

}  // namespace resolver
