// The noise floor of each signal group: the residual a perfect model would leave.
//
// Two estimates, and which one is used is said:
//  - standstill: where the log holds still (>= kMinStandstillSamples samples in
//    stretches of >= 10, each after its first 0.1 s, where the converter's loop and the
//    shaft still ring after a stop), the spread of each signal about its stretch's mean is the
//    sensor's own noise; moving adds the quantization of the quantized channels
//    (uniform: LSB^2 / 12 each, the LSB read off the data).
//  - second differences: per speed bin, the signal's second differences after
//    removing a saturated harmonic model of the angle (orders up to the bin's
//    Nyquist limit, at most 16, plus mechanical orders 1-2 with a reference);
//    for white noise of sigma, var(r[i+1] - 2 r[i] + r[i-1]) = 6 sigma^2. Built on
//    normal equations of the differenced rows: one pass, any log length.
// The standstill estimate is used when the log has one (the rule: the
// sensor's own noise); a second-difference floor far above it (> 3x) is reported,
// since it means noise that only motion makes (timing jitter) or structure the
// saturated model cannot follow.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "daemon/core/model/fit_row.h"
#include "daemon/core/model/least_squares.h"

namespace resolver {

struct FloorEstimate {
  double chosen = 0.0;            ///< the floor the fit uses [unit of the group]
  double second_difference = 0.0; ///< NaN when not estimable
  double standstill = 0.0;        ///< NaN without enough standstill
  double quantization = 0.0;      ///< the moving quantization part included in `standstill`
  std::int64_t standstill_samples = 0;
  std::string source;             ///< "standstill" or "second_differences"
};

struct FloorReport {
  FloorEstimate rd, sc, cur;
  [[nodiscard]] GroupFloors floors() const { return {rd.chosen, sc.chosen, cur.chosen}; }
};

/// Quanta of the raw channels [rad for angles, counts for sin/cos]: 0 = not quantized.
struct ChannelQuanta {
  double rd = 0.0, ref = 0.0, sincos = 0.0;
  double amplitude = 1.0;  ///< [counts] of the envelopes (sin/cos quantum / amplitude = angle quantum)
};

inline constexpr std::int64_t kMinStandstillSamples = 200;

/// Estimates every group's floor over `rows` (the groups the rows have).
/// `sample_period` [s]; `use_standstill` false = second differences only (--moving-only).
[[nodiscard]] FloorReport estimate_floors(std::span<const FitRow> rows, double sample_period, bool reference,
                                          const ChannelQuanta& quanta, bool use_standstill);

/// The smallest step of a quantized channel (0 when the values are not on a lattice
/// coarser than 1e-9 of their range).
[[nodiscard]] double channel_quantum(std::span<const double> values);

}  // namespace resolver
