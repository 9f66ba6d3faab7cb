// What a run showed, for the end-of-run report: estimate, position error
// before/after compensation, dq ripple before/after. Pure accumulation.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "daemon/core/estimation/sample_processor.h"

namespace resolver {

/// Welford running mean/variance.
struct RunningStats {
  std::int64_t n = 0;
  double mean = 0.0;
  double m2 = 0.0;
  void add(double x) {
    ++n;
    const double d = x - mean;
    mean += d / static_cast<double>(n);
    m2 += d * (x - mean);
  }
  /// Standard deviation about the mean (= RMS with the mean removed).
  [[nodiscard]] double stddev() const {
    return n > 1 ? std::sqrt(m2 / static_cast<double>(n - 1)) : std::numeric_limits<double>::quiet_NaN();
  }
  [[nodiscard]] double value_or_nan() const { return n > 0 ? mean : std::numeric_limits<double>::quiet_NaN(); }
};

struct RunSummary {
  // Position error against the reference, once compensation is active [rad].
  // The mean is removed: a constant offset between reference and resolver
  // zero (mounting) is not an error the amplitude-imbalance model addresses.
  RunningStats eps_raw;
  RunningStats eps_comp;
  // Ripple amplitudes [A] at the end of the run (coherent average over the
  // processor's last ripple_revolutions electrical revolutions), taken only
  // once the estimator has converged, so "compensated" is compensated.
  RippleSet ripple;
  bool have_ripple = false;

  /// Accumulates one processed sample (only after the estimator converged,
  /// so "compensated" means compensated with a converged estimate).
  void add(const SampleOutput& out, const SampleProcessor& proc);
};

}  // namespace resolver
