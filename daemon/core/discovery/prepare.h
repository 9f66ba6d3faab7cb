// From a log's samples to the rows a fit uses (discovery's first step; pure).
//
//   samples ─► signals present (>= 90 % of the samples carry them)
//          ─► true angle: the reference encoder (unwrapped, x p_r), or without one
//             the self-calibrated ideal angle (self_calibration.h)
//          ─► motion: speed, acceleration, standstill, direction (motion.h)
//          ─► rows: R/D angle error, sin/cos angle error and radius, dq currents in
//             the true frame (fit_row.h); flags: moving, outlier (outliers.h),
//             validation fold, revolution block
//          ─► noise floors (noise_floor.h)
// Standstill samples enter no fit and never count as revolutions; they give the
// noise floor. Any motion works: out-and-back sweeps, reversals, steps, ramps,
// slow turns, p_r = 1. What the fit needs of the motion is checked per design
// (coverage.h), not here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "daemon/core/discovery/motion.h"
#include "daemon/core/discovery/noise_floor.h"
#include "daemon/core/discovery/outliers.h"
#include "daemon/core/model/fit_row.h"
#include "daemon/core/sample.h"

namespace resolver {

struct DiscoveryInput {
  int p_r = 3;  ///< resolver pole pairs
  int p = 3;    ///< motor pole pairs
  std::vector<Sample> samples;
};

enum class DirectionFilter : std::uint8_t { kBoth, kForward, kBackward };

/// Where an earlier chunk of a log left the rotor (add_chunk), so that the next chunk goes
/// on as the whole log does: the direction held through a standstill, and backlash's
/// take-up (the travel since the last reversal's turning point). Only with a reference:
/// its zero is the same in every chunk, so the angle between two chunks is known.
struct MotionContinuation {
  bool valid = false;
  double direction = 1.0;        ///< +1 / -1, held at the last sample
  double last_angle = 0.0;       ///< [rad, mechanical] the last sample's true angle, in [0, 2 pi)
  bool reversed = false;         ///< the rotor has reversed (the take-up's travel counts from then)
  double turning_offset = 0.0;   ///< [rad] the last reversal's turning point minus the last angle
  double extremum_offset = 0.0;  ///< [rad] the furthest angle in the held direction minus the last angle
};

struct PrepareOptions {
  DirectionFilter direction = DirectionFilter::kBoth;
  /// Standstill samples are not used at all (no standstill floor either).
  bool moving_only = false;
  /// The reference's zero is on the rotor d axis ([bench] reference_aligned): a
  /// constant position error is then the mounting offset. Otherwise it is the
  /// reference's own zero, a free constant (a nuisance) of every fit.
  bool reference_aligned = false;
  /// [counts] the envelopes' amplitude the radius is normalised by; 0 = the median
  /// radius of these samples. A later chunk of a long log takes its first chunk's, so
  /// the chunks share one scale (and the merge one gain: merged_statistics.h).
  double amplitude = 0.0;
  /// [s] the sample time that is the rows' t = 0; NaN = the first usable sample's. A
  /// later chunk of a long log takes its first chunk's: a drift over time is then one
  /// line across the chunks, as in the whole log.
  double time_origin = std::numeric_limits<double>::quiet_NaN();
  /// Where the log's earlier chunk left the rotor (PreparedLog::continuation); not valid =
  /// the log starts here (the play taken up in the direction of the first motion).
  MotionContinuation continuation;
};

struct PreparedLog {
  int p_r = 3, p = 3;
  bool reference = false;  ///< true angle from the reference encoder
  bool reference_aligned = false;  ///< its zero is the rotor d axis (PrepareOptions)
  bool rd = false;         ///< R/D angle rows
  bool sincos = false;     ///< sin/cos rows
  bool currents = false;   ///< dq rows (needs the reference)
  double amplitude = 0.0;      ///< [counts] median sin/cos radius
  double sample_period = 0.0;  ///< [s] median
  double time_origin = 0.0;    ///< [s] the sample time of the rows' t = 0 (PrepareOptions)
  /// Where these samples leave the rotor: the next chunk's PrepareOptions::continuation
  /// (valid with a reference).
  MotionContinuation continuation;
  std::vector<FitRow> rows;
  /// Of each row, its sample: rows[i] came from DiscoveryInput::samples[sample_of_row[i]]
  /// (the raw signals behind a row, e.g. for resolver-model export-data).
  std::vector<std::size_t> sample_of_row;
  MotionSummary motion;        ///< of the mechanical angle (true, or self-calibrated / p_r)
  FloorReport floors;
  ChannelQuanta quanta;
  std::vector<OutlierSignal> outliers;
  std::int64_t samples_in = 0;            ///< samples given
  std::int64_t without_angle = 0;         ///< no R/D angle or sin/cos
  std::int64_t without_reference = 0;     ///< dropped in reference mode
  std::int64_t excluded_direction = 0;    ///< moving the other way (--direction)
  std::int64_t unusable_self_calibration = 0;
  std::string fold_rule;                  ///< how the validation folds were drawn
  std::vector<std::string> notes;         ///< what the log lacks, assumptions
  /// A pooled fit's logs, in FitRow::part order (pool.h); empty for one log.
  std::vector<std::string> part_names;

  [[nodiscard]] int part_count() const { return part_names.empty() ? 1 : static_cast<int>(part_names.size()); }
  [[nodiscard]] std::int64_t fitted_rows() const;
  [[nodiscard]] std::int64_t outlier_rows() const;
  /// [rev] electrical revolutions travelled while moving.
  [[nodiscard]] double electrical_revolutions() const;
};

/// Builds the rows. Throws std::invalid_argument saying what is missing: no
/// angle signal (R/D or sin/cos) on 90 % of the samples, pole pairs < 1, fewer
/// than 64 moving samples (the message gives the motion seen).
[[nodiscard]] PreparedLog prepare_log(const DiscoveryInput& input, const PrepareOptions& options = {});

}  // namespace resolver
