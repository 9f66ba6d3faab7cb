// The fitted model as a drive firmware loads it: a table of the correction over
// one mechanical revolution, indexed by the MEASURED angle (what the drive has),
// plus the speed- and direction-dependent terms as scalars and the table's
// Fourier coefficients.
//
//   theta_c = theta_meas + table(theta_meas_m) + omega d + p_r (h/2) sign(omega)
//
// table(x) is the static correction: the model's inversion (compensator.h) at zero
// speed, theta_meas_m the measured mechanical angle (the resolver angle unwrapped
// over p_r plus the cycle offset; with p_r = 1 the resolver angle itself), sampled at
// N points and interpolated linearly (periodic). The interpolation error bound is
// measured on a grid 16 times finer and stated with the table. delay d and backlash
// h are not in the table: they depend on speed and direction.
#pragma once

#include <string>
#include <vector>

#include "daemon/core/model/model.h"

namespace resolver {

struct CalibrationTable {
  int p_r = 1;
  int p = 1;
  std::vector<double> correction;     ///< [rad, resolver electrical] at theta_meas_m = 2 pi i / N
  double interpolation_error = 0.0;   ///< [rad] max |exact - linear interpolation| on a 16x finer grid
  double delay = 0.0;                 ///< [s] the model's delay (0 without one)
  double backlash = 0.0;              ///< [rad, mechanical] the model's play h (0 without one)
  /// Fourier series of the table over theta_m: correction = a[0] + sum a[n] cos(n x) + b[n] sin(n x).
  std::vector<double> a, b;
  std::vector<std::string> model;     ///< the model's effect references
  std::vector<ModelParameter> parameters;

  /// The correction [rad] at a measured mechanical angle x [rad] (linear, periodic).
  [[nodiscard]] double at(double x) const;
};

/// Tabulates `model` at `points` (>= 8) points. `fourier_orders` coefficients are kept.
/// Throws std::invalid_argument for fewer than 8 points.
[[nodiscard]] CalibrationTable tabulate(const Model& model, int points, int fourier_orders = 64);

/// resolverd --calibration: compensates with a table instead of a live fit.
class TableCompensator {
 public:
  explicit TableCompensator(CalibrationTable table) : table_(std::move(table)) {}
  /// The corrected resolver angle [rad, wrapped] for a measured one at resolver
  /// electrical speed omega [rad/s]. `theta_m_ref` (NaN: none) lets it learn which
  /// electrical cycle of the mechanical turn the resolver is in.
  [[nodiscard]] double correct(double theta_meas, double omega, double theta_m_ref);
  [[nodiscard]] const CalibrationTable& table() const { return table_; }

 private:
  CalibrationTable table_;
  AngleUnwrapper unwrap_;
  double cycle_offset_ = 0.0;
  bool cycle_known_ = false;
  double direction_ = 1.0;
};

}  // namespace resolver
