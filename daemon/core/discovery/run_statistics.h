// Statistics that merge (issue 24): a run's fit kept as the quadratic it leaves,
// so runs fitted apart (other processes, other machines) combine into the pooled fit
// without their samples.
//
// A run's statistics are the normal equations of one pass (least_squares.h) at the
// run's own converged fit, over its nuisance columns, the model's parameters and the
// candidate effects' columns (each at its neutral value), per signal group and per
// validation fold. In the parameter step delta = z - z_r about that point the pass
// leaves the residual
//     RSS(delta) = yy - 2 delta'b + delta'M delta.
// Moved to another point z0 (d = z_r - z0, so delta = delta0 - d) the same quadratic is
//     yy + 2 d'b + d'M d - 2 delta0'(b + M d) + delta0'M delta0,
// so runs linearised at their own solutions add exactly once moved to one point. Each
// run keeps its own nuisance columns (design.h "Parts": its reference zero, amplitude,
// operating point), as a pooled fit of the logs does. For parameters the prediction is
// linear in the merge is the pooled fit; for nonlinear ones (a tracking loop, envelope
// effects at large magnitude) it is the pooled Gauss-Newton step from the runs' own
// solutions, exact to second order in how far those lie apart.
//
// Pure; the file format is tools/model/stats_file.h.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/discovery/pool.h"
#include "daemon/core/discovery/prepare.h"
#include "daemon/core/discovery/ranking.h"
#include "daemon/core/model/least_squares.h"

namespace resolver {

struct RunStatistics {
  PoolLayout layout;  ///< the bench and the signals: a merge needs the same in every run
  std::vector<std::string> effects;  ///< the model fitted to the run (references, e.g. "harmonics(k3)")
  /// The run's own fit of that model (standard errors robust where it has the revolutions):
  /// what a merge compares each run with the others by.
  std::vector<ModelParameter> params;
  /// Every column's name: the run's nuisances ("nuisance.sr_gain"), then the model's
  /// parameters, then the candidates' ("quadrature.beta").
  std::vector<std::string> columns;
  /// The candidate terms the run's residual asked for (ranking.h residual_candidate_terms,
  /// e.g. "harmonics(k5)", "harmonics(k5,k5_q)"): subsets of one candidate term's columns
  /// per effect, scored apart by the merge as explain scores them.
  std::vector<std::string> candidate_sets;
  int nuisance_columns = 0;  ///< the first columns are the run's own constants
  int model_columns = 0;     ///< then the model's parameters; the rest are candidates
  /// Internal coordinate (design.h) of every column at the linearisation point: the
  /// run's fit for the model's (or the start values: at_merged), 0 for nuisances and
  /// candidates (neutral).
  Eigen::VectorXd point;
  /// Every model term's parameter values (all of its parameters, in effect order).
  std::vector<std::vector<double>> values;
  double frame_shift = 0.0;  ///< [rad] the run's sensor zero in its fit's frame
  PassStatistics stats;      ///< at `point`, columns as above
  FloorReport floors;        ///< the run's own noise floors
  std::int64_t fitted_rows = 0;
  std::int64_t samples = 0;
  double span_s = 0.0;
  double electrical_revolutions = 0.0;
  MotionSummary motion;  ///< what a candidate needs of the motion is judged on the runs' together
  std::vector<std::string> notes;  ///< the run's fit's notes
  /// Impulsive samples the run's fit left out (outliers.h) and, per group, the rows
  /// they are and the squared residual they carry at the run's fit: a merge is then
  /// explained only if its signals are at the floor with them too, as explain.
  std::int64_t outlier_samples = 0;
  std::vector<std::int64_t> outlier_rows = std::vector<std::int64_t>(kGroups, 0);
  std::vector<double> outlier_rss = std::vector<double>(kGroups, 0.0);
  /// Signal faults that held for a large part of the run (DiscoveryOptions::untrusted_input):
  /// a merge with any is never "explained".
  std::vector<std::string> untrusted;
  /// Model effects the run held at their start values (FitStartValues::held: its rows
  /// alone cannot separate them): its statistics are at that point, and the merge's
  /// value of them is one Gauss-Newton step from there. Only in a refit pass's memory;
  /// a statistics file never has any.
  std::vector<std::string> held;
  /// The statistics are at the start values of the pass (FitStartValues::at_start: the
  /// merged fit of an earlier pass), not at the run's own fit. Only in memory.
  bool at_merged = false;
};

/// Fits `effects` to the prepared run to convergence and takes one more pass there
/// with every candidate the run's layout allows (a fittable catalog effect not in the
/// model, default parameters; one that needs a reference, an aligned reference or
/// currents the run lacks is left out). Throws std::invalid_argument as fit_prepared,
/// unless the effects it cannot separate are in options.start.held: then the others are
/// fitted and those held at their start values (RunStatistics::held).
[[nodiscard]] RunStatistics run_statistics(const PreparedLog& log, std::span<const std::string> effects,
                                           const DiscoveryOptions& options);

/// A merged fit of several runs.
struct MergedFit {
  std::vector<std::string> effects;
  std::vector<ModelParameter> params;    ///< value and formal standard error
  std::vector<ModelParameter> nuisance;  ///< each run's constants, named "...[run]"
  std::vector<SignalResidual> signals;   ///< rms (linearised), floor (pooled), held back, rows
  std::vector<Candidate> candidates;     ///< the common candidates not in the model, best BIC first
  std::vector<std::string> not_evaluated;
  /// Each run's own fit against the other runs' (compare_with_pool), largest |z| first.
  std::vector<PoolDisagreement> comparisons;
  FloorReport floors;                    ///< rows-weighted over the runs
  std::int64_t rows = 0;
  int runs = 0;
  bool explained = false;  ///< every signal within explained_ratio x its floor, held back too
  /// The model's nonlinear effects some run had only as a candidate: fitted by one
  /// linearised step, so the merge neither says explained nor proposes an effect.
  std::vector<std::string> linearised;
  /// Candidates whose score is their exact fit: statistics made again with each in the
  /// model and merged (take_exact_refit), not the one linearised step from zero.
  std::vector<std::string> refitted;
  /// Model effects some run held at their start values (RunStatistics::held), and of the
  /// refitted candidates those: fitted by Gauss-Newton steps of merges over passes, not
  /// to convergence on each run.
  std::vector<std::string> held;
  /// Pairs of proposed candidates, the best joint linearised step first (ranking.h
  /// screen_pairs, from the merged statistics): what the two-effect search fits.
  std::vector<ScreenedPair> screened_pairs;
  /// Two candidates whose merged exact fit together reaches the floor where neither alone
  /// does (stats_run.h find_missing_pair_from_logs), with their fitted parameters.
  std::vector<std::string> missing_pair;
  std::vector<ModelParameter> missing_pair_params;
  /// The two-effect search would run but could not (no logs to read again): a candidate
  /// named alone short of the floor may be the wrong one, and the verdict says so.
  bool pair_search_skipped = false;
  bool untrusted = false;  ///< some run's signals were faulty for long: never explained, nothing proposed
  /// The model's prediction is not linear in its parameters (least_squares.h
  /// strictly_linear): the merge is one Gauss-Newton step from the runs' points, exact
  /// only where they are the merged fit (FitStartValues::at_start passes iterate it).
  bool nonlinear = false;
  std::int64_t outlier_samples = 0;  ///< left out of the runs' fits (SignalResidual::rms_with_outliers)
  bool rd = false;         ///< the position error is the R/D angle's (ranking.h score_candidate)
  double bic = std::numeric_limits<double>::quiet_NaN();  ///< of the model's merged solution (fit_support.h bic_of)
  double weighted_rss = 0.0;  ///< its residual, each signal over its floor squared
  /// The weighted residual at the merge's point (the reference run's), the runs' constants
  /// solved: where every run is at one point (RunStatistics::at_merged) that point's exact
  /// cost, which Gauss-Newton over passes compares points by.
  double cost_at_point = 0.0;
  /// [floors] The largest RMS change of a run's fitted signals from its own fit to the
  /// merged one (the model's parameters): the merge of a nonlinear model is exact to
  /// second order in this, so Gauss-Newton over passes is needed only where it is not small.
  double run_move = 0.0;
  std::vector<std::string> notes;
};

/// Merges `runs` (named `names`, e.g. their files) and fits `effects` (empty: the
/// runs' model) from them: the parameters' columns must be in every run (a model
/// effect or a candidate of each). Throws std::invalid_argument naming the run that
/// differs (pole pairs, signals, model, a missing column) or when fewer than one run
/// or the columns are not separable. The result does not depend on the runs' order
/// (beyond rounding): they are moved to the point of the run with the most rows.
/// `log_of` (empty: every run a log of its own) gives each run's log: the runs of one
/// log (its chunks, stats --chunk) share its reference zero, as the log's fit in memory
/// has one; each run keeps its own amplitude and operating point (its sin/cos are
/// normalised by its own amplitude when prepared).
/// `lambda` > 0 damps the model's step (Levenberg-Marquardt, least_squares.h solve_step):
/// Gauss-Newton over passes (stats_run.h) steps back so from a point that went uphill.
[[nodiscard]] MergedFit merge_runs(const std::vector<RunStatistics>& runs, const std::vector<std::string>& names,
                                   std::span<const std::string> effects, const DiscoveryOptions& options,
                                   std::span<const int> log_of = {}, double lambda = 0.0);

/// The candidates of `m` whose linearised step is not their fit (ranking.h exact_refits:
/// envelope effects at real magnitudes, nonlinear parameters), to be refitted from
/// statistics made again with each in the model. None when the merge needs no effect or
/// is not judged (explained, untrusted, linearised).
[[nodiscard]] std::vector<std::string> candidates_to_refit(const MergedFit& m, const DiscoveryOptions& options);

/// Replaces candidate `effect` of `m` by its exact fit: `with` merges the same runs'
/// statistics made with the model plus `effect` (every run fitted to convergence with
/// it), as explain refits a log in memory. The candidates are ordered again (ranking.h order_ranked).
void take_exact_refit(MergedFit& m, const std::string& effect, const MergedFit& with, const DiscoveryOptions& options);

}  // namespace resolver
