// Ripple of the d/q currents at 1x, 2x and 6x the electrical frequency,
// measured by a single-bin DFT over each complete electrical revolution.
//
// For a revolution of N samples at angles theta_e,i the order-k amplitude is
//     A_k = (2/N) | sum_i (x_i - mean(x)) exp(-j k theta_e,i) |,
// exact for x = A cos(k theta_e + phi) sampled uniformly in angle (constant
// speed). The revolution's mean is removed because the angle used is itself
// distorted (the raw R/D angle is non-uniform in time): without it the large
// DC of i_q would leak into order k as 2 I_q eps_k, a ripple that is not in
// the current at all. Computed in one pass as
// sum x w - mean(x) sum w, w = exp(-j k theta). Orders are those dq_t carries
// (docs/ARCHITECTURE.md §4): 1x (current-sensor offsets), 2x
// (amplitude imbalance, Hwang eqs. 15-16; gain mismatch), 6x (dead time).
// Noise sets a floor of about 2 sigma / sqrt(N) per order and revolution. The
// published amplitude is |mean of the complex coefficients of the last K
// revolutions| (coherent: every revolution's phase is referenced to the same
// theta_e), which keeps a steady ripple and lowers the noise floor to
// ~2 sigma / sqrt(N K). At the simulator's default sigma_i = 20 mA and N = 200
// that is 2.5 mA per revolution, 0.9 mA with K = 8.
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <vector>

namespace resolver {

inline constexpr std::array<int, 3> kRippleOrders = {1, 2, 6};

struct RippleAmplitudes {
  std::array<double, 3> d{};  ///< [A] i_d ripple at kRippleOrders
  std::array<double, 3> q{};  ///< [A] i_q ripple at kRippleOrders
};

class RevolutionRipple {
 public:
  /// revolutions_averaged: K, the coherent averaging window (>= 1).
  explicit RevolutionRipple(int revolutions_averaged = 8)
      : window_(revolutions_averaged < 1 ? 1 : revolutions_averaged) {}

  /// Feeds one sample: theta_e continuous (unwrapped) [rad], i_d, i_q [A].
  /// Returns true when this sample completed a revolution; `last()` then holds
  /// the ripple of that revolution.
  bool update(double theta_e, double i_d, double i_q) {
    return update(theta_e, std::cos(theta_e), std::sin(theta_e), i_d, i_q);
  }
  /// Same, with cos/sin of theta_e already computed (the caller's Park transform has them).
  bool update(double theta_e, double cos_e, double sin_e, double i_d, double i_q);

  [[nodiscard]] const RippleAmplitudes& last() const { return last_; }
  [[nodiscard]] bool valid() const { return revolutions_ > 0; }
  [[nodiscard]] std::int64_t revolutions() const { return revolutions_; }
  void reset() { *this = RevolutionRipple(window_); }

 private:
  bool started_ = false;
  bool in_revolution_ = false;
  std::int64_t rev_index_ = 0;
  int n_ = 0;
  std::array<std::complex<double>, 3> sum_d_{};
  std::array<std::complex<double>, 3> sum_q_{};
  std::array<std::complex<double>, 3> sum_w_{};
  double sum_x_d_ = 0.0;
  double sum_x_q_ = 0.0;
  // Ring of the last K revolutions' normalised complex coefficients.
  int window_;
  std::vector<std::array<std::complex<double>, 3>> ring_d_, ring_q_;
  std::size_t ring_next_ = 0;
  RippleAmplitudes last_;
  std::int64_t revolutions_ = 0;
};

}  // namespace resolver
