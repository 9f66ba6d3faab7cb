// What the rotor did: speed, acceleration, standstill and direction per sample,
// and how far it travelled. Real benches sweep out and back, stop, reverse, step
// their speed; the fit must know which samples move (standstill samples never
// enter a fit and never count as revolutions) and which way.
//
// Speed and acceleration: a local quadratic (Savitzky-Golay) fit of the angle over
// +-5 samples within a time-contiguous run (a gap of more than 3 median sample
// periods ends a run).
// Standstill, with hysteresis: over the fit window (10 sample periods) the rotor
// travels less than kStopNoiseMultiple (3) x the angle's sample noise sigma (leave
// "moving"), or more than kMoveNoiseMultiple (6) x sigma (enter "moving"). sigma is
// the robust standard deviation of the angle's second differences / sqrt(6): the
// sensor noise and the quantization, whatever their source. Direction: the sign of
// the speed while moving, held through a standstill.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace resolver {

struct MotionSample {
  double omega = 0.0;      ///< [rad/s] speed of the input angle
  double accel = 0.0;      ///< [rad/s^2]
  double direction = 1.0;  ///< +1 / -1
  bool moving = false;
};

struct MotionSummary {
  std::int64_t samples = 0;
  std::int64_t moving = 0;
  std::int64_t standstill = 0;
  std::int64_t forward = 0;          ///< moving samples forward
  std::int64_t backward = 0;         ///< moving samples backward
  int reversals = 0;                 ///< direction changes between moving stretches
  int standstills = 0;               ///< stretches of standstill
  double travelled = 0.0;            ///< [rad] of the input angle over moving samples
  double span_s = 0.0;               ///< [s] first to last sample
  double omega_min = 0.0, omega_max = 0.0;  ///< [rad/s] signed speed range while moving
  double angle_noise = 0.0;          ///< [rad] sigma behind the standstill threshold
};

/// Analyses a continuous (unwrapped) angle [rad] at times t [s] (increasing).
/// Cannot fail; fewer than 3 samples are all "standstill". `initial_direction` (+1 / -1)
/// is the direction held before the first sample (a later chunk of a log: the earlier
/// chunk's last); 0 = the first motion's.
[[nodiscard]] std::vector<MotionSample> analyse_motion(std::span<const double> t, std::span<const double> angle,
                                                       MotionSummary& summary, double initial_direction = 0.0);

/// Robust (MAD) standard deviation of a series' second differences / sqrt(6): the
/// sample noise of a smooth signal [unit of the values]. 0 for fewer than 3 values.
[[nodiscard]] double second_difference_sigma(std::span<const double> values);

}  // namespace resolver
