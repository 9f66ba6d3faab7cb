// Which phase-current samples the live dq ripple replaces by their neighbours' line:
// impulses (an inverter's switching edges on a current sensor's ADC; resolver-sim's
// current_outliers).
//
// Why: the ripple is a DFT over each electrical revolution (revolution_ripple.h), and an
// impulse is broadband. One-sided 10 A spikes at 50/s on phase current a (2 kHz) read as a
// 170 mA ripple at 1x theta_e and 105 mA at 6x where the currents carry 1.3 and 1.0 mA: a
// current sensor's offset and a dead time that are not there.
//
// Test, one sample at a time with no look-ahead (the ripple closes revolutions as samples
// arrive): i_d and i_q (with the R/D angle) against the line through the last two samples
// that passed, extrapolated to this sample's time. A sample off that line by more than
// kThreshold robust sigmas in either is a spike. The robust sigma is 1.4826 x the median
// |residual| over the last kWindow samples (all of them: a few spikes in the window move
// the median by a few percent). Under white noise the residual's sigma is sqrt(6) of the
// samples' (1 + 4 + 1); a smooth ripple's curvature, (k w dt)^2 of its amplitude per
// sample, enters the scale. Twelve sigmas: never under Gaussian noise (P < 1e-32). After
// a spike the line reaches r sample periods out, and the limit grows with its noise,
// sqrt((1 + (1 + r)^2 + r^2) / 6). The spike's stand-in is that line's value (noise up to
// 5 sigma at r = 3): a tenth of a 10 A spike, against a sample left out of the DFT, which
// leaks the 2x ripple into every order.
//
// A level that moved (a load step, a standstill's end) is not a spike: after kMaxRun
// samples in a row off the line the line starts again from the current sample, as it does
// across a gap in time longer than kMaxGap sample periods.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace resolver {

class CurrentSpikeGate {
 public:
  static constexpr double kThreshold = 12.0;
  static constexpr std::size_t kWindow = 64;
  static constexpr int kMaxRun = 4;
  static constexpr double kMaxGap = 4.0;
  /// The robust sigmas are taken again every this many samples (two medians of kWindow
  /// every 16 samples cost a fit-off replay ~10 % of its time; the noise changes slower
  /// than 256 samples, 26 ms at 10 kHz).
  static constexpr std::size_t kScaleEvery = 256;

  /// Whether the sample at time `t` [s] with dq currents `i_d`, `i_q` [A] is to be used
  /// (false: a spike, counted).
  bool pass(double t, double i_d, double i_q);
  /// Samples found spikes so far.
  [[nodiscard]] std::int64_t rejected() const { return rejected_; }
  /// [A] After pass() returned false: the line's i_d, i_q at that sample's time, what the
  /// caller uses in its place.
  struct Estimate {
    double d = 0.0, q = 0.0;
  };
  [[nodiscard]] const Estimate& line() const { return estimate_; }

 private:
  struct Point {
    double t = 0.0, d = 0.0, q = 0.0;
  };
  /// Starts the line again at `p` (the residual window is kept: the noise did not change).
  void restart(const Point& p);
  [[nodiscard]] double sigma(const std::array<double, kWindow>& window) const;

  Point last_{}, before_{};
  int points_ = 0;  ///< how many of last_, before_ hold a sample (0-2)
  int run_ = 0;     ///< samples in a row off the line
  std::array<double, kWindow> res_d_{}, res_q_{};
  std::size_t filled_ = 0, next_ = 0;
  double sigma_d_ = 0.0, sigma_q_ = 0.0;
  std::size_t since_scale_ = 0;
  std::int64_t rejected_ = 0;
  Estimate estimate_{};
};

}  // namespace resolver
