// Impulsive samples (EMI spikes, bit errors): found by a robust test, counted,
// kept out of fits and floors, and reported.
//
// Test: the second difference d_i = y_{i+1} - 2 y_i + y_{i-1} of a signal over
// consecutive samples. A spike of size a at i gives the pattern (a, -2a, a), so
// sample i is an outlier when |d_i| exceeds kThreshold (12) robust standard
// deviations of d and is the largest of its three neighbours. The robust scale
// is the MAD of d, bounded below by half the mean |d| (a quantized, slow signal
// has a zero MAD). For Gaussian noise 12 sigma is never reached (P < 1e-32); the
// smooth part of the signal (the error harmonics the fit explains) changes d by
// (k omega dt)^2 of its amplitude and enters the scale, not the test.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace resolver {

struct OutlierSignal {
  std::string signal;          ///< "position_error", "sin_cos", "i_dq"
  std::int64_t count = 0;
  double largest = 0.0;        ///< largest |spike| [unit of the signal]
  double scale = 0.0;          ///< robust sigma of the second differences [unit]
  std::vector<double> times;   ///< [s] of the first ones (at most 10)
};

/// Marks outliers of `y` (consecutive samples; `usable[i]` false = skip and break
/// the sequence) in `flags` (set to true). Returns the summary for `signal`.
OutlierSignal find_outliers(std::span<const double> t, std::span<const double> y, const std::vector<bool>& usable,
                            std::vector<bool>& flags, const std::string& signal);

}  // namespace resolver
