#pragma once
// The currents' operating point: the machine's steady d and q current under the ripple
// the current-side effects add (docs/ARCHITECTURE.md section 8).

#include <Eigen/Core>

namespace resolver {

struct CurrentOperatingPoint {
  double i_d = 0.0;  ///< [A] the measured currents' constant part
  double i_q = 0.0;
  /// True when the samples covered the electrical angle well enough to separate the
  /// constant from the ripple; false: the plain mean (the ripple may leak into it).
  bool ripple_separated = false;
};

/// The constant of a least-squares fit of i_d and i_q to 1 and the ripple orders the
/// current-side effects make (1x theta_e: sensor offsets; 2x: sensor gains; 6x and 12x:
/// dead time; docs/EFFECTS.md). Over whole electrical turns at even speed this is the
/// mean; where the angle is not covered evenly (a reversal's slow crossing of zero speed,
/// a ramp ending mid-turn) the mean takes a share of the ripple, which the sensor gains'
/// exact prediction (current_gain_mismatch.h) would read as a wrong machine current:
/// ~1e-3 of 10 A on a bench-like log, 3-8 standard errors of the gains (docs/ACCURACY.md).
class CurrentOperatingPointFit {
 public:
  static constexpr int kColumns = 9;  ///< the constant, then cos and sin of each order

  /// One sample: the motor electrical angle [rad] and the measured d and q currents [A].
  void add(double theta_e, double i_d, double i_q);
  [[nodiscard]] CurrentOperatingPoint result() const;

 private:
  Eigen::Matrix<double, kColumns, kColumns> ata_ = Eigen::Matrix<double, kColumns, kColumns>::Zero();
  Eigen::Matrix<double, kColumns, 2> atb_ = Eigen::Matrix<double, kColumns, 2>::Zero();
  long long n_ = 0;
};

}  // namespace resolver
