// Running mean and variance of a stream of values (Welford): one pass, no stored
// samples, no cancellation of a large mean. Pure.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace resolver {

/// Welford running mean/variance.
struct RunningStats {
  std::int64_t n = 0;
  double mean = 0.0;
  double m2 = 0.0;  ///< sum of squared deviations from the mean
  void add(double x) {
    ++n;
    const double d = x - mean;
    mean += d / static_cast<double>(n);
    m2 += d * (x - mean);
  }
  /// Sample variance about the mean (NaN below two values).
  [[nodiscard]] double variance() const {
    return n > 1 ? m2 / static_cast<double>(n - 1) : std::numeric_limits<double>::quiet_NaN();
  }
  /// Standard deviation about the mean (= RMS with the mean removed).
  [[nodiscard]] double stddev() const { return std::sqrt(variance()); }
  [[nodiscard]] double value_or_nan() const { return n > 0 ? mean : std::numeric_limits<double>::quiet_NaN(); }
};

}  // namespace resolver
