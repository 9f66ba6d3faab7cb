// What a run showed, for the end-of-run report: estimate, position error
// before/after compensation, dq ripple before/after. Pure accumulation.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "daemon/core/estimation/sample_processor.h"
#include "daemon/core/running_stats.h"

namespace resolver {

/// One error statistic and what it covers.
struct ErrorStats {
  RunningStats stats;           ///< [rad, resolver electrical]
  double sum_squares = 0.0;     ///< for the RMS including the mean
  double t_first = 0.0, t_last = 0.0;  ///< [s] sample time of the first and last sample counted
  void add(double eps, double t) {
    if (stats.n == 0) t_first = t;
    t_last = t;
    stats.add(eps);
    sum_squares += eps * eps;
  }
  /// RMS including the mean [rad] (NaN when empty).
  [[nodiscard]] double rms() const {
    return stats.n > 0 ? std::sqrt(sum_squares / static_cast<double>(stats.n)) : std::numeric_limits<double>::quiet_NaN();
  }
};

struct RunSummary {
  // Position error against the reference [rad, resolver electrical], over every
  // sample with a reference (the whole log) and over the moving ones; and, once the
  // compensation is active, raw and compensated side by side over the same samples.
  // RMS includes the mean (a mounting offset is an error too); the mean and the
  // spread about it are reported beside it.
  ErrorStats raw_all, raw_moving;
  ErrorStats compared_raw, compared_comp;  ///< moving samples since compensation started
  std::int64_t samples = 0, moving = 0, with_reference = 0;
  double t_first = 0.0, t_last = 0.0;
  // Samples with an angle published compensated, with or without a reference to
  // measure them against, and when the first was (NaN: never).
  std::int64_t compensated = 0;
  double t_compensation_start = std::numeric_limits<double>::quiet_NaN();
  // Ripple amplitudes [A] at the end of the run (coherent average over the
  // processor's last ripple_revolutions electrical revolutions), taken only
  // once the estimator has converged, so "compensated" is compensated.
  RippleSet ripple;
  bool have_ripple = false;
  /// Phase-current samples the ripple took from their neighbours' line (spikes; over the run).
  std::int64_t current_spikes = 0;

  /// Accumulates one processed sample at time t [s].
  void add(const SampleOutput& out, const SampleProcessor& proc, double t);
};

}  // namespace resolver
