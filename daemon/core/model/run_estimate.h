// A run's estimate from its windows' fits (issue 26, "one story of uncertainty"):
// resolverd fits the model window by window (16 revolutions each) and compensates
// with the newest window, which follows a sensor that drifts; the run's estimate,
// what the report, the last estimate_t and the calibration file give, is every
// window's combined, so it covers the whole run as resolver-model's fit of the same
// log does.
//
// Combination: per parameter, the inverse-variance weighted mean of the windows'
// values (weights 1/se_i^2): for windows that are independent samples of the same
// sensor this is the least-squares estimate of all of them together. Its standard
// error: with at least kSpreadWindows windows, from their scatter about the mean,
// se^2 = sum w_i (x_i - mean)^2 / ((K - 1) sum w_i) (the formal error scaled by the
// Birge ratio, so a drift between windows widens it); with fewer, the formal
// 1 / sqrt(sum w_i). A window whose error is not finite and positive gets no weight.
// Kept as sums (memory flat however long the daemon runs): chi^2 = sum w x^2 - (sum w x)^2
// / sum w, exact enough for values whose spread is >= 1e-7 of their size.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "daemon/core/model/model.h"

namespace resolver {

class RunEstimate {
 public:
  /// Windows from which the standard error is their scatter (the same 8 as the
  /// revolution-to-revolution spread of a single fit, model_discovery.h).
  static constexpr int kSpreadWindows = 8;

  /// One window's fitted model. A model of other effects or pole pairs than the
  /// windows so far (a reload changed them) starts the combination again. Cannot fail.
  void add(const Model& window, std::int64_t samples, double revolutions);

  [[nodiscard]] int windows() const { return windows_; }
  [[nodiscard]] std::int64_t samples() const { return samples_; }
  [[nodiscard]] double revolutions() const { return revolutions_; }
  /// The combined model (the last window's effects; empty before a window).
  [[nodiscard]] Model combined() const;
  /// What the combined standard errors are from, in words.
  [[nodiscard]] std::string basis() const;

 private:
  struct Sums {
    std::string name;
    double w = 0.0, wx = 0.0, wxx = 0.0;  ///< of the windows with a usable error
    double plain = 0.0;                   ///< sum of every window's value
  };
  Model last_;
  std::vector<Sums> sums_;  ///< per fitted parameter, in parameters() order
  int windows_ = 0;
  std::int64_t samples_ = 0;
  double revolutions_ = 0.0;
};

}  // namespace resolver
