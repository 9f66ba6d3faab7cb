// Model discovery (docs/ARCHITECTURE.md §8): fit a model to a log, compare the residual with
// the noise floor, say where it fails, and rank the effects not in the model by
// how much of the residual each explains.
//
// Files, one job each (all pure maths, no I/O):
//   prepare.h        samples -> rows: true angle, motion, signals, outliers, floors, folds
//   coverage.h       what the motion must cover for the orders a model fits
//   ../model/        the Model, its Design and the least-squares solver on
//                    sufficient statistics (normal equations per signal group and fold)
//   breakdowns.h     the residual by harmonic, speed, time, direction; whiteness;
//                    robust standard errors; plot series (one streaming pass)
//   ranking.h        candidates from the catalog and the residual's orders, BIC, ERR,
//                    ambiguity (effects the log cannot tell apart)
//   narration.h      where it fails and the verdict in words; the suggested custom effect
//   model_discovery  (this file) fit_model / explain_model: the order of the steps
//
// Units: angles [rad] (resolver electrical unless a name says mechanical), speeds
// [rad/s] resolver electrical, time [s], currents [A].
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/discovery/noise_floor.h"
#include "daemon/core/discovery/outliers.h"
#include "daemon/core/discovery/prepare.h"
#include "daemon/core/model/model.h"

namespace resolver {

class CustomEffects;

/// The highest harmonic order an offline analysis breaks the residual into: the
/// catalog's highest winding harmonic (k20).
inline constexpr int kOfflineReportOrder = 20;

/// Where a fit starts instead of the effects' defaults (issue 23: a chunk's exact refit
/// started from the merged fit of the whole log, as the in-memory refit starts from
/// the model's converged fit).
struct FitStartValues {
  /// Start values by parameter name ("quadrature.beta"); names the model lacks are ignored.
  std::vector<ModelParameter> values;
  /// Effect references whose start values are a converged fit: fitted from that start
  /// only (least_squares.h fit_design `settled`).
  std::vector<std::string> settled;
  /// Effect references a run may hold at their start values when its own rows cannot
  /// separate them (a play in a chunk that turns one way): run_statistics.h.
  std::vector<std::string> held;
  /// A run's statistics are taken at these values (the merged fit of an earlier pass:
  /// run_statistics.h), each run's frame shift fitted there, not at the run's own fit:
  /// the next merge is then a Gauss-Newton step relinearised on every run's rows.
  bool at_start = false;
};

struct DiscoveryOptions {
  /// A signal is explained when its residual rms <= explained_ratio x its noise floor (issue 4: 1.5).
  double explained_ratio = 1.5;
  /// A candidate is proposed when it lowers the BIC by more than this (Kass & Raftery:
  /// a difference above 10 is "very strong" evidence).
  double proposal_bic_drop = 10.0;
  /// Harmonic orders 0..max_report_order of theta (and of theta_m, theta_e) in the breakdown.
  /// 8 by default: resolverd's live windows pay (2N + 1)^2 per row and accumulator, and
  /// on a busy core a slower fit starves the socket. resolver-model sets
  /// kOfflineReportOrder: a saturation pattern's orders are then all seen and proposed
  /// together (ranking's family candidate).
  int max_report_order = 8;
  /// Propose harmonic families (every significant order at once) and each order with
  /// its quadrature part besides single in-phase orders: offline (resolver-model). Off
  /// for resolverd's live windows, where their columns slowed every window that misses
  /// an effect (and, on one emulated CPU, the socket reader beside it).
  bool harmonic_families = false;
  /// Refit the proposed candidates (the first kNonlinearRefits as listed, ranking.cpp) to
  /// convergence with the model, not only those whose one linearised step is known not
  /// to be their fit (ranking.h needs_exact_refit): with
  /// a nonlinear model (the default's gain error goes through atan2) even a linear
  /// candidate's step is first order. A drifting excitation (0.1 %/s) was named with g 6
  /// standard errors from its fit. Offline (resolver-model); the live windows save the time.
  bool refit_proposed = false;
  /// Speed bins of the residual breakdown (equal width over the signed speeds seen; empty bins dropped).
  int speed_bins = 6;
  /// Time windows of the breakdown (a residual that changes over time is outside the catalog).
  int time_bins = 5;
  /// Called with the fraction done in [0, 1] (may be empty).
  std::function<void(double)> progress;
  /// Points of the per-sample series kept for plots (angle-stratified); 0 = none.
  int series_points = 0;
  /// Rank the candidates even when the model explains the log (never proposed then).
  bool rank_when_explained = true;
  /// A run's statistics keep every candidate's columns (run_statistics.h); without, only
  /// the model's: a candidate's exact refit needs no others.
  bool statistics_candidates = true;
  /// Start values of the fit (fit_prepared); empty = the effects' defaults.
  FitStartValues start;
  /// Slicing of the log's samples (direction, moving only).
  PrepareOptions prepare;
  /// The config's [[model.custom]] effects (may be null): usable in models and ranked as candidates.
  const CustomEffects* customs = nullptr;
  /// Signal faults that held for a large part of the log (resolver-model: from the same
  /// health monitor as resolverd's): never "explained" while any is listed.
  std::vector<std::string> untrusted_input;
};

/// resolver-model's settings: every harmonic order to kOfflineReportOrder, harmonic
/// families, every proposed candidate refitted (what the live windows leave out for
/// time); the rest as DiscoveryOptions' defaults.
[[nodiscard]] DiscoveryOptions offline_discovery_options();

/// A value with its standard error (NaN: not identifiable / not computed).
struct SignalResidual {
  std::string signal;        ///< "position_error" [rad], "sin_cos" [fraction of amplitude ~ rad] or "i_dq" [A]
  double rms = 0.0;          ///< residual rms after the fit, over the fitted samples
  double floor = 0.0;        ///< noise floor
  double raw_rms = 0.0;      ///< rms with only the nuisance fitted
  double held_back_rms = 0.0;  ///< cross-validated: fitted on one fold, evaluated on the other (NaN: no folds)
  double rms_with_outliers = 0.0;  ///< including the outlier samples the fit left out
  std::int64_t rows = 0;
  std::int64_t rows_with_outliers = 0;  ///< rows of rms_with_outliers
};

struct HarmonicResidual {
  int order = 0;            ///< harmonic order n of the angle
  double amplitude = 0.0;   ///< amplitude of a_n sin + b_n cos (|a_0| for n = 0)
  double phase = 0.0;       ///< [rad] atan2(b_n, a_n): 0 = in phase with sin n theta
};

struct SpeedBinResidual {
  double omega_lo = 0.0, omega_hi = 0.0;  ///< [rad/s] resolver electrical (signed)
  double rpm_mid = 0.0;                   ///< [r/min] mechanical, bin centre (signed)
  double rms = 0.0;                       ///< [rad] position-error residual
  double order2_amplitude = 0.0;          ///< [rad] at 2 theta; NaN when the bin's angles do not cover 2 theta
  std::int64_t samples = 0;
};

struct TimeBinResidual {
  double t_lo = 0.0, t_hi = 0.0;   ///< [s] from the first sample
  double rms = 0.0;                ///< [rad] position-error residual
  double mean = 0.0;               ///< [rad] its mean
  double order2_amplitude = 0.0;   ///< [rad] at 2 theta; NaN when not covered
  std::int64_t samples = 0;
};

struct DirectionResidual {
  int direction = 1;       ///< +1 forward, -1 backward
  std::int64_t samples = 0;
  double rms = 0.0;        ///< [rad] position-error residual
  double mean = 0.0;       ///< [rad] its mean (an offset that flips with the direction is backlash or delay)
};

/// Residual whiteness (MATLAB resid, SysIdentPy): the autocorrelation of the
/// position-error residual at lags 1..lags against its 99 % band +-2.58/sqrt(N).
struct Whiteness {
  int lags = 0;
  double band = 0.0;
  double max_abs = 0.0;   ///< largest |autocorrelation| over the lags
  int outside = 0;        ///< lags outside the band
  std::int64_t samples = 0;
};

/// Decimated per-sample series of the final fit for plots (stratified over the
/// angle: every angle bin is represented). Empty vectors for absent signals.
struct ResidualSeries {
  std::vector<double> t;             ///< [s]
  std::vector<double> theta;         ///< [rad] true resolver electrical angle, wrapped
  std::vector<double> theta_e;       ///< [rad] true motor electrical angle, wrapped (currents)
  std::vector<double> rpm;           ///< [r/min] mechanical speed
  std::vector<double> eps_measured;  ///< [rad] position error
  std::vector<double> eps_model;     ///< [rad] the model's prediction of it
  std::vector<double> i_d_raw, i_q_raw;    ///< [A] dq currents with the raw R/D angle
  std::vector<double> i_d_comp, i_q_comp;  ///< [A] with the R/D angle corrected by the model
  std::vector<double> i_d_ref, i_q_ref;    ///< [A] with the reference angle
  std::vector<double> i_d_model, i_q_model;  ///< [A] the model's prediction of the reference-frame dq
};

/// One log of a pooled fit: its residual with the shared parameters and its own
/// nuisance constants (pool.h).
struct PartResidual {
  std::string name;               ///< the log
  std::int64_t rows = 0;          ///< its fitted rows
  double position_rms = 0.0;      ///< [rad] R/D angle's (NaN without one)
  double sincos_rms = 0.0;        ///< [1] sin/cos angle and radius (NaN without them)
  double dq_rms = 0.0;            ///< [A] (NaN without currents)
};

/// What the statistics cover.
struct SampleAccount {
  std::int64_t samples_in = 0;          ///< samples the log gave
  std::int64_t rows = 0;                ///< with an angle (and the reference when there is one)
  std::int64_t fitted = 0;              ///< moving, not outliers, not excluded: the fit's samples
  std::int64_t moving = 0;
  std::int64_t standstill = 0;
  std::int64_t outliers = 0;
  std::int64_t excluded = 0;            ///< by --direction or unusable without a reference
  std::int64_t without_angle = 0;
  std::int64_t without_reference = 0;
  double span_s = 0.0;
  double revolutions_electrical = 0.0;  ///< travelled while moving
  double revolutions_mechanical = 0.0;
  int reversals = 0;
  int standstills = 0;
  std::string fold_rule;                ///< held-back validation folds
  std::string units = "resolver electrical rad (position error), fraction of amplitude (sin/cos), A (dq)";
};

struct ModelFit {
  std::vector<std::string> effects;          ///< the model's effect references
  std::vector<ModelParameter> params;            ///< fitted parameters (no nuisance)
  std::vector<ModelParameter> nuisance;          ///< the nuisance constants (operating point, amplitude, offsets)
  Model model;                               ///< the fitted model (values, standard errors)
  std::vector<SignalResidual> signals;
  double residual_rms_rad = 0.0;             ///< position-error residual [rad]
  double noise_floor_rad = 0.0;              ///< its floor [rad]
  std::vector<HarmonicResidual> harmonics;       ///< position-error residual by order of theta
  std::vector<HarmonicResidual> harmonics_mech;  ///< by order of theta_m (with a reference)
  std::vector<HarmonicResidual> harmonics_id;    ///< [A] i_d residual by order of theta_e
  std::vector<HarmonicResidual> harmonics_iq;    ///< [A] i_q residual by order of theta_e
  std::vector<SpeedBinResidual> speed_bins;
  std::vector<TimeBinResidual> time_bins;
  std::vector<DirectionResidual> directions;
  Whiteness whiteness;
  FloorReport floors;
  SampleAccount account;
  std::vector<OutlierSignal> outliers;
  double rms_with_outliers_rad = 0.0;        ///< position-error residual including the outlier samples
  double bic = 0.0;                          ///< n ln(RSS_w / n) + k ln n over all weighted rows
  std::int64_t rows = 0;                     ///< weighted rows (every signal's)
  int parameters = 0;                        ///< k, including nuisance columns
  bool reference = false;
  bool sincos_used = false;
  bool currents_used = false;
  bool converged = true;                     ///< evaluated residual = the fit's linearised one (notes say)
  bool explained = false;                    ///< every signal <= ratio x floor, held back too, outliers not mattering
  bool untrusted = false;                    ///< DiscoveryOptions::untrusted_input listed faulty signals: never explained
  bool robust_errors = false;                ///< standard errors from the revolution-to-revolution spread
  int error_revolutions = 0;                 ///< revolution blocks of the fit (the spread's, when robust)
  int passes = 0;                            ///< passes over the rows
  std::vector<std::string> notes;
  ResidualSeries series;
  /// A pooled fit's logs (empty for one log).
  std::vector<PartResidual> parts;
};

struct Candidate {
  std::string effect;               ///< the reference to add, e.g. "harmonics(k5)"
  double residual_after_rad = 0.0;  ///< position-error residual rms with it added
  double sincos_residual_after = 0.0;
  double dq_residual_after = 0.0;
  double score = 0.0;               ///< BIC with it added (lower is better)
  double bic_drop = 0.0;            ///< BIC(model) - score
  double err = 0.0;                 ///< share of the model's weighted residual it removes (error reduction ratio)
  bool proposed = false;            ///< bic_drop > proposal_bic_drop
  bool reaches_floor = false;       ///< every signal <= ratio x floor with it added
  std::string reason;               ///< one sentence of physics + the fitted values
  std::vector<ModelParameter> params;
  double weighted_rss = 0.0;
  std::vector<std::string> fits_as_well;  ///< candidates this log cannot tell from it
  /// A harmonic family (every significant order at once): named first only when no
  /// smaller candidate reaches the floor (the simplest explanation first).
  bool family = false;
  /// Fitted to convergence with the model (ranking.h exact refits), not one linearised
  /// step: its params are a fit a later window may start from.
  bool refitted = false;
  /// Its values and score are one linearised step from neutral although its fit is not
  /// (ranking.h needs_exact_refit; beyond the refits' count): approximate, and said so.
  bool stepped = false;
  /// The model term it goes in place of ("" = added to the model): the model with it added
  /// is not separable from its start values, the two being aliases at first order
  /// (fit_support.h aliased_terms; a mechanical harmonic at a whole electrical order and
  /// the winding harmonics of that order). Its score is that of the model with the swap.
  std::string replaces;

  /// The change to the model it stands for, as a summary names it: "adding X" or "X in
  /// place of Y"; `imperative`: "add X" or "put X in place of Y".
  [[nodiscard]] std::string change(bool imperative = false) const {
    if (replaces.empty()) return (imperative ? "add " : "adding ") + effect;
    return (imperative ? "put " : "") + effect + " in place of " + replaces;
  }
};

/// Whether a candidate that leaves `weighted_rss_after` (a row at its floor weighs 1)
/// removes most of what the model leaves above the floors of `signals` (`rows`: the
/// model's fitted rows over every signal; `rd`: the position error counts). Such an
/// effect is named although it does not reach the floor alone.
[[nodiscard]] bool removes_most_excess(const std::vector<SignalResidual>& signals, std::int64_t rows, bool rd,
                                       double weighted_rss_after);

enum class Verdict : std::uint8_t { kExplained, kMissingEffect, kUnexplained };
[[nodiscard]] std::string_view to_string(Verdict v);

/// What the fit's standard errors are from, in words every program prints the same:
/// "robust: revolution-to-revolution spread of N revolutions" or "formal: residual
/// variance (N revolutions, the spread needs 8)".
[[nodiscard]] std::string std_error_basis(const ModelFit& f);

struct Explanation {
  ModelFit fit;
  std::vector<Candidate> candidates;        ///< best (lowest score) first
  Verdict verdict = Verdict::kExplained;
  std::vector<std::string> where_it_fails;
  std::string summary;
  std::vector<std::string> not_evaluated;   ///< effects skipped, with why
  std::vector<std::string> missing_pair;    ///< two effects that only together reach the floor
  std::string suggested_custom;             ///< a [[model.custom]] block describing the residual (unexplained)
};

/// Effects this version can fit: the registry's fittable ones.
[[nodiscard]] std::vector<std::string_view> fittable_effects();

/// Fits the model named by `effects` (references, model_spec.h; empty = nuisance
/// only). Throws std::invalid_argument naming the effect when it is unknown, when
/// a needed signal is absent (reference, currents), when the motion does not cover
/// the model's orders (coverage.h), or when the log has too little motion.
[[nodiscard]] ModelFit fit_model(const DiscoveryInput& input, std::span<const std::string> effects,
                                 const DiscoveryOptions& options = {});

/// fit_model plus the ranked candidates and the verdict. Throws like fit_model.
[[nodiscard]] Explanation explain_model(const DiscoveryInput& input, std::span<const std::string> effects,
                                        const DiscoveryOptions& options = {});

/// Sets `model`'s parameters named in `start` (names it lacks ignored) and returns which
/// of its terms are settled (least_squares.h fit_design's flags, in term order).
std::vector<bool> apply_start_values(const FitStartValues& start, Model& model);

/// The same on rows already prepared (the live window, several passes of the discovery loop).
[[nodiscard]] ModelFit fit_prepared(const PreparedLog& log, std::span<const std::string> effects,
                                    const DiscoveryOptions& options = {});
[[nodiscard]] Explanation explain_prepared(const PreparedLog& log, std::span<const std::string> effects,
                                           const DiscoveryOptions& options = {});

}  // namespace resolver
