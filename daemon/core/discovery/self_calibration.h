// Without a reference encoder: the ideal angle the resolver should have read,
// from the resolver's own angle (Hanselman III.A's speed-smoothed ideal angle,
// extended to any motion).
//
// Each moving stretch (one direction, no standstill, no gap in time) is cut into
// windows of at least two electrical revolutions and 200 samples (a shorter
// stretch is one window). Per window the measured, unwrapped angle is fitted by
//   a cubic in time  +  sum_{k<=K} a_k sin(k phi) + b_k cos(k phi)
// with phi the measured wrapped angle and K = min(8, the Nyquist order of the
// window's speed): the cubic is the smooth motion, the harmonics the periodic
// error riding on it. The cubic alone is the ideal angle. A window that turns less
// than one electrical revolution cannot tell the two apart: its samples are not
// used (counted).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "daemon/core/discovery/motion.h"

namespace resolver {

struct SelfCalibration {
  std::vector<double> ideal;   ///< [rad] smoothed angle per sample (continuous)
  std::vector<bool> usable;    ///< false: in no window of at least one revolution
  int windows = 0;
  std::int64_t unusable = 0;   ///< moving samples in windows shorter than a revolution
};

/// `angle` is the measured angle unwrapped [rad, resolver electrical], `wrapped`
/// the same wrapped to [0, 2pi), `t` [s], `motion` per sample, `dt` the sample period [s].
[[nodiscard]] SelfCalibration self_calibrate(std::span<const double> t, std::span<const double> angle,
                                             std::span<const double> wrapped, std::span<const MotionSample> motion,
                                             double dt);

}  // namespace resolver
