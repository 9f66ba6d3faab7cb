// The live model-fit window (docs/ARCHITECTURE.md §8, issue 4 "Live"): collects joined samples
// until they cover a number of resolver electrical revolutions, then hands them
// over as one DiscoveryInput for fit_model / explain_model. Windows do not
// overlap. A window that never turns far enough (a stopped motor) is handed over
// at max_samples anyway, so the caller can say "insufficient data" instead of
// staying silent. Pure: no threads, no I/O.
#pragma once

#include <cstddef>
#include <cstdint>

#include "daemon/core/angles.h"
#include "daemon/core/discovery/prepare.h"

namespace resolver {

struct ModelWindowConfig {
  double revolutions = 16.0;          ///< resolver electrical revolutions per window (R/D angle)
  std::size_t max_samples = 100000;   ///< hand over at this many samples even if it turned less
};

class ModelWindow {
 public:
  explicit ModelWindow(const ModelWindowConfig& config) : config_(config) {}

  /// Adds one sample (samples without an R/D angle are kept for the fit but do not
  /// advance the revolution count). Pole pairs that change mid-window restart it.
  /// Returns true when the window is complete: take() it.
  bool add(const Sample& sample, int p_r, int p);
  /// The collected window; the next add() starts a new one.
  [[nodiscard]] DiscoveryInput take();

  [[nodiscard]] std::size_t size() const { return input_.samples.size(); }
  /// [rev] resolver electrical revolutions travelled so far, either way.
  [[nodiscard]] double revolutions() const;
  /// [rad/s] resolver electrical, signed: the net angle travelled over the time it took,
  /// first to last sample with an angle (0 before two such samples). An out-and-back
  /// window's is near zero: its operating point is no one speed.
  [[nodiscard]] double mean_speed() const;

 private:
  ModelWindowConfig config_;
  DiscoveryInput input_;
  AngleUnwrapper unwrap_;
  bool have_angle_ = false;
  double anchor_ = 0.0;  ///< [rad] unwrapped angle where the last counted turn ended
  std::int64_t turns_ = 0;
  double partial_ = 0.0;  ///< [rev] of the turn in progress
  double first_angle_ = 0.0, first_t_ = 0.0;  ///< [rad], [s] of the first sample with an angle
  double last_angle_ = 0.0, last_t_ = 0.0;    ///< [rad] unwrapped, [s] of the last
};

}  // namespace resolver
