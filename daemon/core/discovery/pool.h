// Pooled fits (issue 24): several logs of one bench fitted together. The sensor's
// parameters are shared; each log keeps its own nuisance constants (its reference's
// zero, its envelopes' amplitude, its operating point: design.h "Parts"). A log
// whose parameters, fitted alone, disagree with the pool beyond their errors is
// named: a parameter that changed between runs is news for the engineer.
//
// pool_logs joins prepared logs into one PreparedLog whose rows carry FitRow::part;
// every later step (fit, ranking, narration) runs on it unchanged. Pure.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/discovery/prepare.h"

namespace resolver {

/// Joins `logs` (prepared alone, same options) named `names`. Time runs on across
/// the logs in the order given, with a gap between them (no history, whiteness
/// lag or delay reaches across a boundary); revolution blocks and validation folds
/// stay each log's own. Throws std::invalid_argument naming the log when the logs
/// differ in pole pairs or in the signals they carry (a pooled fit needs one
/// layout), or when fewer than two logs or more than 65535 are given.
[[nodiscard]] PreparedLog pool_logs(std::vector<PreparedLog> logs, const std::vector<std::string>& names);

/// What runs fitted together must share: the bench and the signals.
struct PoolLayout {
  int p_r = 0, p = 0;
  bool reference = false, reference_aligned = false, rd = false, sincos = false, currents = false;
};
[[nodiscard]] PoolLayout pool_layout(const PreparedLog& log);

/// Throws std::invalid_argument naming `name` when `other` differs from `first` (named
/// `first_name`) in pole pairs or in a signal.
void check_same_layout(const PoolLayout& first, const PoolLayout& other, const std::string& first_name,
                       const std::string& name);

/// Each log's floors weighted by its rows (one weight per group for all its rows):
/// the rows-weighted pooled variance.
[[nodiscard]] FloorReport pool_floor_reports(const std::vector<const FloorReport*>& floors,
                                             const std::vector<double>& rows);

/// Adds one log's motion to a pool's (`first`: the pool's first log).
void add_motion(MotionSummary& into, const MotionSummary& m, bool first);

/// One parameter of one log against the other logs.
struct PoolDisagreement {
  std::string log;
  std::string parameter;
  double value = 0.0, std_error = 0.0;          ///< fitted on the log alone
  double others = 0.0, others_std_error = 0.0;  ///< the other agreeing logs' own fits, inverse-variance weighted
  double pooled = 0.0;                          ///< fitted on every log together
  double z = 0.0;  ///< (value - others) / sqrt(se^2 + se_others^2)
};

/// A log disagrees when |z| exceeds this: 4 standard errors (a 6e-5 chance per
/// parameter for a normal error; the errors are the revolution spread's, robust to
/// correlated residuals).
inline constexpr double kPoolDisagreementZ = 4.0;

/// Every (log, parameter) of `alone` (each log's own fit, in pool order) against the
/// other logs that agree (the most distant log beyond kPoolDisagreementZ leaves the
/// consensus while three or more remain: an odd log is named alone and does not pull
/// the value the others are compared with; of two logs that differ both are named),
/// largest |z| first; those beyond kPoolDisagreementZ disagree. Parameters without
/// a finite standard error are skipped.
[[nodiscard]] std::vector<PoolDisagreement> compare_with_pool(const ModelFit& pooled, const std::vector<ModelFit>& alone,
                                                              const std::vector<std::string>& names);

/// Logs prepared alone and their pool (pool_logs of copies: each log's own fit needs its rows).
struct PooledLogs {
  std::vector<PreparedLog> logs;
  PreparedLog pool;
};

/// Prepares each input alone (options.prepare) and pools them. Throws
/// std::invalid_argument naming the log when one cannot be prepared or the logs
/// cannot be pooled (pool_logs).
[[nodiscard]] PooledLogs prepare_pooled(const std::vector<const DiscoveryInput*>& inputs,
                                        const std::vector<std::string>& names, const PrepareOptions& options);

/// Each log fitted alone with `effects`, compared with the others (compare_with_pool).
struct LogComparison {
  std::vector<ModelFit> alone;               ///< each log fitted alone (same model)
  std::vector<std::string> alone_failed;     ///< per log: why its own fit failed ("" = it did not)
  std::vector<PoolDisagreement> comparisons; ///< largest |z| first
};

/// Fits every log of `pooled` alone with `effects` and compares them with each other
/// (and `fit`, the pooled fit of the same effects, for its values).
[[nodiscard]] LogComparison compare_logs(const PooledLogs& pooled, const std::vector<std::string>& names,
                                         const ModelFit& fit, std::span<const std::string> effects,
                                         const DiscoveryOptions& options);

/// The notes that name each disagreeing log (into a fit's notes).
[[nodiscard]] std::vector<std::string> disagreement_notes(const std::vector<PoolDisagreement>& comparisons);

/// A pooled fit or explanation with each log's own fit beside it.
struct PooledExplanation {
  Explanation pooled;        ///< on every log (fit.parts: each log's residual; notes name disagreeing logs)
  std::vector<std::string> names;  ///< the logs, in pool order
  LogComparison logs;
};

/// prepare_pooled, the pooled fit (explain: and its explanation), compare_logs.
[[nodiscard]] PooledExplanation explain_pooled(const std::vector<const DiscoveryInput*>& inputs,
                                               const std::vector<std::string>& names,
                                               std::span<const std::string> effects, const DiscoveryOptions& options,
                                               bool explain);

}  // namespace resolver
