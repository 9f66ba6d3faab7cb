// One streaming pass over the rows at the fitted model: the residual broken down
// by harmonic order (of theta, theta_m, theta_e), by speed bin, time window and
// direction; its whiteness; the per-revolution scores behind the robust standard
// errors; the residual including the outlier samples; and the plot series. Every
// breakdown is a small accumulation (normal equations or sums per bin): memory
// does not grow with the log.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <span>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/discovery/prepare.h"
#include "daemon/core/model/design.h"

namespace resolver {

struct ResidualPass {
  std::vector<HarmonicResidual> harmonics, harmonics_mech, harmonics_id, harmonics_iq;
  std::vector<SpeedBinResidual> speed_bins;
  std::vector<TimeBinResidual> time_bins;
  std::vector<DirectionResidual> directions;
  Whiteness whiteness;
  ResidualSeries series;
  double rss_position = 0.0;           ///< [rad^2] over fitted rows (position-error signal)
  std::int64_t n_position = 0;
  double rss_position_with_outliers = 0.0;
  std::int64_t n_position_with_outliers = 0;
  /// Per signal group (rd, sin/cos, dq), the residual of the fitted rows with the
  /// prediction evaluated (the fit's own figure is linearised).
  double rss[3] = {0.0, 0.0, 0.0};
  std::int64_t n[3] = {0, 0, 0};
  /// Per signal group (rd, sin/cos, dq), the residual including the outlier samples.
  double rss_with_outliers[3] = {0.0, 0.0, 0.0};
  std::int64_t n_with_outliers[3] = {0, 0, 0};
  /// Sum over revolution blocks of g g', g = the block's weighted score J'W r on `score_columns`.
  Eigen::MatrixXd score_outer;
  int blocks = 0;
  /// Per pooled part (FitRow::part) and signal group, the fitted rows' residual.
  std::vector<std::array<double, 3>> part_rss;
  std::vector<std::array<std::int64_t, 3>> part_n;
};

/// The fitted nuisance constants (design.h): what the residual is measured about.
struct NuisanceValues {
  double rd = 0.0, sa = 0.0, sr = 0.0, d = 0.0, q = 0.0;
};

/// Runs the pass. `design` holds the fitted model (no candidates); `score_columns`
/// are the columns whose robust covariance is wanted (nuisance + model); `nuisance`
/// has one entry per pooled part (design.h "Parts").
[[nodiscard]] ResidualPass residual_pass(const Design& design, const PreparedLog& log, const GroupFloors& floors,
                                         std::span<const int> score_columns, const DiscoveryOptions& options,
                                         std::span<const NuisanceValues> nuisance);

}  // namespace resolver
