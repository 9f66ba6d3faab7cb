// Model discovery (DESIGN 7): fit a set of catalog effects to a log's samples,
// compare the residual with the noise floor, and rank the catalog effects not
// in the model by how much of the residual each explains.
//
// Data flow (pure maths, no I/O; the caller reads the log):
//
//   samples ─► prepare: true angle theta (reference, or a speed-smoothed ideal
//   │          angle when there is none), speed omega, rows
//   │            position error  eps = theta_true - theta_rd           [rad]
//   │            sin/cos         s/A - sin theta, c/A - cos theta     [1 ~ rad] (reference only)
//   │            dq currents     i_d, i_q in the frame at theta_e = p theta_m  [A] (reference only)
//   │          noise floor of each signal (second differences of a saturated fit)
//   └► fit: weighted linear least squares, one column per effect parameter
//      (effect_signatures.h), rows weighted by 1/floor so signals combine;
//      tracking_loop is the one nonlinear effect (omega_n, searched on a grid)
//   └► explain: refit with each missing catalog effect, BIC ranking, verdict.
//
// Units: angles [rad] (resolver electrical unless a name says mechanical),
// speeds [rad/s] resolver electrical, time [s].
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/sample.h"

namespace resolver {

/// Discovery reads the shared sample (daemon/core/sample.h).
using DiscoverySample = Sample;

struct DiscoveryInput {
  int p_r = 3;  ///< resolver pole pairs
  int p = 3;    ///< motor pole pairs
  std::vector<DiscoverySample> samples;
};

struct DiscoveryOptions {
  /// A signal is explained when its residual rms <= explained_ratio x its noise floor (issue 4: 1.5).
  double explained_ratio = 1.5;
  /// A candidate is proposed when it lowers the BIC by more than this (Kass & Raftery:
  /// a difference above 10 is "very strong" evidence).
  double proposal_bic_drop = 10.0;
  /// Harmonic orders 0..max_report_order of theta in the residual breakdown.
  int max_report_order = 8;
  /// Speed bins of the residual breakdown (equal width over the speeds seen; empty bins dropped).
  int speed_bins = 6;
  /// Time windows of the residual breakdown (a residual that changes over time is
  /// outside the catalog: no effect here is a function of time).
  int time_bins = 5;
  /// Called with the fraction done in [0, 1] during explain (may be empty).
  std::function<void(double)> progress;
  /// Points of the per-sample series kept in ModelFit::series for plots (evenly
  /// decimated); 0 = none.
  int series_points = 0;
  /// Rank the candidates even when the model already explains the log (they are
  /// never proposed then). resolverd's live windows turn this off: ranking is
  /// ~90 % of a window's cost and says nothing new while the model holds.
  bool rank_when_explained = true;
};

/// A value with its standard error (NaN: not identifiable / not computed).
struct ParamValue {
  std::string name;  ///< "effect.param", e.g. "amplitude_imbalance.alpha"
  double value = 0.0;
  double std_error = 0.0;
};

struct SignalResidual {
  std::string signal;       ///< "position_error" [rad], "sin_cos" [fraction of amplitude] or "i_dq" [A]
  double rms = 0.0;         ///< residual rms after the fit
  double floor = 0.0;       ///< noise floor estimated from the data
  double raw_rms = 0.0;     ///< rms before any effect is fitted (nuisance only)
  std::int64_t rows = 0;
};

struct HarmonicResidual {
  int order = 0;            ///< harmonic order n of theta (resolver electrical)
  double amplitude = 0.0;   ///< [rad] amplitude of a_n sin + b_n cos (|a_0| for n = 0)
  double phase = 0.0;       ///< [rad] atan2(b_n, a_n): 0 = in phase with sin n theta
};

struct SpeedBinResidual {
  double omega_lo = 0.0, omega_hi = 0.0;  ///< [rad/s] resolver electrical
  double rpm_mid = 0.0;                   ///< [r/min] mechanical, bin centre
  double rms = 0.0;                       ///< [rad] position-error residual
  double order2_amplitude = 0.0;          ///< [rad] residual amplitude at 2 theta
  std::int64_t samples = 0;
};

/// Decimated per-sample series of the final fit, for plots. Vectors are empty when
/// the signal is absent (currents need phase currents and the reference).
struct ResidualSeries {
  std::vector<double> t;             ///< [s]
  std::vector<double> theta;         ///< [rad] true resolver electrical angle, wrapped to [0, 2 pi)
  std::vector<double> rpm;           ///< [r/min] mechanical speed
  std::vector<double> eps_measured;  ///< [rad] position error theta_true - theta_rd
  std::vector<double> eps_model;     ///< [rad] the model's prediction of it
  std::vector<double> i_d_raw, i_q_raw;    ///< [A] dq currents with the raw R/D angle
  std::vector<double> i_d_comp, i_q_comp;  ///< [A] with the R/D angle corrected by the model
  std::vector<double> i_d_ref, i_q_ref;    ///< [A] with the reference angle
};

struct TimeBinResidual {
  double t_lo = 0.0, t_hi = 0.0;   ///< [s] from the first sample
  double rms = 0.0;                ///< [rad] position-error residual
  double order2_amplitude = 0.0;   ///< [rad] residual amplitude at 2 theta
  std::int64_t samples = 0;
};

struct ModelFit {
  std::vector<std::string> effects;
  std::vector<ParamValue> params;
  std::vector<SignalResidual> signals;
  double residual_rms_rad = 0.0;  ///< position error residual [rad]
  double noise_floor_rad = 0.0;   ///< position error floor [rad]
  std::vector<HarmonicResidual> harmonics;  ///< position error residual by order
  std::vector<HarmonicResidual> harmonics_id;  ///< [A] i_d residual by order of theta_e (currents only)
  std::vector<HarmonicResidual> harmonics_iq;  ///< [A] i_q residual by order of theta_e
  std::vector<SpeedBinResidual> speed_bins;
  std::vector<TimeBinResidual> time_bins;  ///< equal-length windows of the log
  double bic = 0.0;               ///< n ln(RSS_w / n) + k ln n over all weighted rows
  std::int64_t rows = 0;
  int parameters = 0;             ///< k, including nuisance columns
  bool reference = false;         ///< eps against the reference encoder (else smoothed ideal angle)
  bool sincos_used = false;       ///< sin/cos rows entered the fit
  bool currents_used = false;     ///< dq current rows entered the fit
  bool explained = false;         ///< every signal <= explained_ratio x floor
  std::vector<std::string> notes; ///< what is missing from the log, assumptions
  ResidualSeries series;          ///< only with DiscoveryOptions::series_points > 0
};

struct Candidate {
  std::string effect;
  double residual_after_rad = 0.0;  ///< position error residual rms with the effect added
  double sincos_residual_after = 0.0;  ///< sin/cos residual rms (0 when not used)
  double dq_residual_after = 0.0;      ///< [A] i_d/i_q residual rms (0 when not used)
  double score = 0.0;               ///< BIC of the model with the effect added (lower is better)
  double bic_drop = 0.0;            ///< BIC(model) - score (> 0: better)
  bool proposed = false;            ///< bic_drop > proposal_bic_drop
  bool reaches_floor = false;       ///< every signal <= explained_ratio x floor after adding it
  std::string reason;               ///< one sentence of physics
  std::vector<ParamValue> params;   ///< the added effect's parameters
  double weighted_rss = 0.0;        ///< sum of (residual / floor)^2 over all rows with the effect added
};

enum class Verdict : std::uint8_t { kExplained, kMissingEffect, kUnexplained };
[[nodiscard]] std::string_view to_string(Verdict v);

struct Explanation {
  ModelFit fit;
  std::vector<Candidate> candidates;      ///< best (lowest score) first
  Verdict verdict = Verdict::kExplained;
  std::vector<std::string> where_it_fails;  ///< sentences; empty when explained
  std::string summary;                      ///< one or two sentences
  std::vector<std::string> not_evaluated;   ///< catalog effects skipped, with why
  /// When no single effect explains the residual but two proposed ones do together:
  /// both, best single first (verdict missing_effect). Empty otherwise.
  std::vector<std::string> missing_pair;
};

/// Effects this version can fit (catalog names).
[[nodiscard]] std::span<const std::string_view> fittable_effects();

/// Fits `effects` (catalog names; may be empty = nuisance only). Throws
/// std::invalid_argument naming the effect when it is unknown or not fittable,
/// when a needed signal is absent (eccentricity and mounting_offset need the
/// reference, current-side effects need the reference and phase currents), or
/// when fewer than two resolver revolutions of R/D samples exist.
[[nodiscard]] ModelFit fit_model(const DiscoveryInput& input, std::span<const std::string> effects,
                                 const DiscoveryOptions& options = {});

/// fit_model plus the ranked candidates and the verdict. Throws like fit_model.
[[nodiscard]] Explanation explain_model(const DiscoveryInput& input, std::span<const std::string> effects,
                                        const DiscoveryOptions& options = {});

}  // namespace resolver
