// Weighted (Gauss-Newton / Levenberg-Marquardt) least squares of a Design over
// fit rows, built on sufficient statistics: each pass over the rows only adds
// to normal equations (normal_equations.h), per signal group so every signal's
// residual follows from them, and per validation fold so the held-back residual
// does too. Any subset of the design's columns (a model with one candidate
// added) is then solved from the same statistics without another pass.
//
// Groups and weights: rd; sc = the sin/cos angle and radius; cur = i_d and i_q.
// Each group's rows are weighted by 1/floor^2 (its noise floor), so the signals
// combine in units of their own noise.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "daemon/core/model/design.h"
#include "daemon/core/model/fit_row.h"
#include "daemon/core/model/normal_equations.h"

namespace resolver {

enum class Group : std::uint8_t { kRd, kSc, kCur };
inline constexpr int kGroups = 3;

/// Noise floor of each group [rad, 1, A]; 0 = the group is not fitted.
struct GroupFloors {
  double rd = 0.0, sc = 0.0, cur = 0.0;
  [[nodiscard]] double of(Group g) const { return g == Group::kRd ? rd : g == Group::kSc ? sc : cur; }
};

/// The sufficient statistics of one pass: per group, all fitted rows and fold A.
struct PassStatistics {
  std::vector<NormalEquations> all;     ///< by Group
  std::vector<NormalEquations> fold_a;  ///< rows without FitRow::kFoldB
  explicit PassStatistics(int columns = 0);
  void merge(const PassStatistics& other);
  /// Fold B = all - fold A.
  [[nodiscard]] NormalEquations fold_b(Group g) const;
};

/// One pass: every fitted row (FitRow::fitted()) evaluated at the design's point;
/// adds the Jacobian rows with the residual y - prediction of each signal the row has.
void accumulate(const Design& design, std::span<const FitRow> rows, const GroupFloors& floors, PassStatistics& out);

/// The solution of one linearised problem on a subset of columns.
struct StepSolution {
  bool ok = false;            ///< false: the columns are not separable with these rows
  Eigen::VectorXd dz;         ///< step in internal coordinates, full length (0 outside the subset)
  Eigen::MatrixXd inverse;    ///< (J'WJ)^-1 on the subset, full size (0 outside)
  double rss_w = 0.0;         ///< weighted residual sum of squares after the step
  double rss[kGroups] = {0.0, 0.0, 0.0};  ///< per group, unweighted
  std::int64_t n[kGroups] = {0, 0, 0};    ///< rows per group
  int k = 0;                  ///< columns solved
};

/// Solves the linearised problem of `stats` on `columns` (empty = all), with
/// Levenberg-Marquardt damping `lambda` (0 = Gauss-Newton). Rank test on the
/// columns scaled to unit diagonal (relative threshold 1e-9): collinear columns
/// (e.g. k3 and alpha without sin/cos) give ok = false.
[[nodiscard]] StepSolution solve_step(const std::vector<NormalEquations>& groups, const GroupFloors& floors,
                                      std::span<const int> columns = {}, double lambda = 0.0);

/// The groups' residual sum of squares, each over its floor squared (a group without a
/// floor is not fitted): the cost at the statistics' point with no column solved.
[[nodiscard]] double weighted_yy(const std::vector<NormalEquations>& groups, const GroupFloors& floors);

/// True when every model term's prediction is linear in its fitted parameters and none
/// shapes the basis: one linearised step is the exact fit, and statistics moved to another
/// point (run_statistics.h) are exact there.
[[nodiscard]] bool strictly_linear(const Design& design);

/// Moves every part's frame shift (design.h) to its least-squares value at the
/// design's parameters, which stay as they are: Gauss-Newton on the position-error
/// constant (with the other nuisance constants) until it moves the shift by < 1e-7 rad,
/// at most `max_passes` passes over the rows. Returns the passes taken (0 when the
/// reference is aligned: no shift).
int fit_frame_shift(Design& design, std::span<const FitRow> rows, const GroupFloors& floors, int max_passes);

/// Result of fitting a design to convergence.
struct FitResult {
  bool ok = false;
  int passes = 0;
  StepSolution last;        ///< the final linearised solution (at the converged point)
  PassStatistics stats;     ///< the statistics of the final pass (at the converged point)
  /// Weighted RSS at the final point with the nuisance constants solved (what the
  /// starts of a multimodal fit are compared by).
  double cost = std::numeric_limits<double>::infinity();
  /// The final point is the solution: the undamped step from it would move the parameters
  /// by less than ~0.3 standard errors (least_squares.cpp step_negligible). False where the
  /// fit ended at its last good point because the damped steps went uphill, or ran out of
  /// passes, with a larger step still to take (nearly collinear terms: the point is where
  /// it stopped, not a fit).
  bool converged = false;
};

/// How far the undamped step `s` from a point of weighted cost `cost` would move the
/// parameters, in standard errors (from how much it lowers the cost); a fit is converged
/// where this is below ~0.3 (FitResult::converged).
[[nodiscard]] double step_in_standard_errors(const StepSolution& s, double cost);

/// Fits the design's model parameters (candidates are not moved): Gauss-Newton,
/// with Levenberg-Marquardt damping when a nonlinear step does not lower the
/// cost; one pass for a linear design, at most `max_passes`. `progress` (may be
/// empty) is called after each pass. A nonlinear parameter whose cost has several
/// valleys is fitted from other starts too, unless its term is `settled` (one flag per
/// design term; empty = none): its values are already a converged fit, whose valley
/// was chosen then (the model's terms when one more effect is refitted with them, a
/// chunk started from the merged fit of the log). With every model term settled the
/// first step moves the nonlinear parameters too (from a neutral start it holds them).
[[nodiscard]] FitResult fit_design(Design& design, std::span<const FitRow> rows, const GroupFloors& floors,
                                   int max_passes = 12, const std::function<void()>& progress = {},
                                   const std::vector<bool>& settled = {});

}  // namespace resolver
