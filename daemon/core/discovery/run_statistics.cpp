#include "daemon/core/discovery/run_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/discovery/fit_support.h"
#include "daemon/core/discovery/merged_statistics.h"
#include "daemon/core/discovery/outliers.h"
#include "daemon/core/discovery/pool.h"
#include "daemon/core/discovery/ranking.h"
#include "daemon/core/effects/registry.h"

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A candidate the run's layout allows: the model lacks it, and the signals it needs are there.
bool signals_allow(const Effect& e, const PreparedLog& log) {
  if (!e.fittable()) return false;
  if (e.needs_reference() && !log.reference) return false;
  if (e.needs_aligned_reference() && !log.reference_aligned) return false;
  return !(e.current_side() && !log.currents);
}

bool candidate_for(const Effect& e, const ModelSpec& spec, const PreparedLog& log) {
  return spec.find(e) == nullptr && signals_allow(e, log);
}

/// The candidates' columns of a run: an effect that asks its residual which of its
/// parameters to try (the harmonic orders: ranking.h residual_candidate_terms) gets one
/// term over every parameter its sets need, and the sets are kept by name for the merge
/// to score each as explain does; every other effect the model lacks, its default term.
void add_candidate_columns(Design& d, const ModelFit& fit, const PreparedLog& log, const DiscoveryOptions& options,
                           std::vector<std::string>& sets) {
  std::vector<const Effect*> answered;
  const std::vector<ModelTerm> terms = residual_candidate_terms(fit, options, &answered);
  for (const Effect* e : effect_registry()) {
    // A term held in the design (RunStatistics::held) is the model's, not a candidate.
    if (std::any_of(d.terms().begin(), d.terms().end(), [&](const DesignTerm& t) { return t.effect == e; })) continue;
    if (std::find(answered.begin(), answered.end(), e) == answered.end()) {
      if (candidate_for(*e, fit.model.spec(), log)) d.add_candidate(ModelTerm{e, default_params(*e)});
      continue;
    }
    if (!signals_allow(*e, log)) continue;
    std::vector<int> params;
    for (const ModelTerm& t : terms) {
      if (t.effect != e) continue;
      params.insert(params.end(), t.params.begin(), t.params.end());
      sets.push_back(t.reference());
    }
    std::sort(params.begin(), params.end());
    params.erase(std::unique(params.begin(), params.end()), params.end());
    if (!params.empty()) d.add_candidate(ModelTerm{e, params});
  }
}


/// The run with the most fitted rows (ties: the first name): every run is moved to
/// its point, so the merge does not depend on the order the runs are given in.
std::size_t reference_run(const std::vector<RunStatistics>& runs, const std::vector<std::string>& names) {
  std::size_t best = 0;
  for (std::size_t r = 1; r < runs.size(); ++r) {
    if (runs[r].fitted_rows > runs[best].fitted_rows ||
        (runs[r].fitted_rows == runs[best].fitted_rows && names[r] < names[best])) {
      best = r;
    }
  }
  return best;
}

/// The merged design: `spec` at the reference run's values, then every candidate
/// column all runs have.
Design merged_design(const ModelSpec& spec, const std::vector<RunStatistics>& runs, std::size_t ref,
                     const DiscoveryOptions& options) {
  const ModelSpec ref_spec = ModelSpec::parse(runs[ref].effects, options.customs);
  std::vector<std::vector<double>> values;
  for (const ModelTerm& t : spec.terms) {
    const auto it = std::find_if(ref_spec.terms.begin(), ref_spec.terms.end(),
                                 [&](const ModelTerm& u) { return u.effect == t.effect; });
    values.push_back(it == ref_spec.terms.end() ? std::vector<double>{}
                                                : runs[ref].values[static_cast<std::size_t>(it - ref_spec.terms.begin())]);
  }
  // No nuisance columns: every run's own constants are profiled out of its statistics
  // (reduce_run), so the merged problem has the shared columns only, whatever the runs.
  Design d(spec, values, {});
  // Candidates: the columns every run has that the model does not, grouped by effect.
  const std::vector<std::string> have = d.column_names();
  std::map<const Effect*, std::vector<int>> extra;
  std::vector<const Effect*> order;
  for (int c = runs[ref].nuisance_columns; c < static_cast<int>(runs[ref].columns.size()); ++c) {
    const std::string& name = runs[ref].columns[static_cast<std::size_t>(c)];
    if (column_index(have, name) >= 0) continue;
    const bool everywhere = std::all_of(runs.begin(), runs.end(), [&](const RunStatistics& r) { return column_index(r.columns, name) >= 0; });
    const std::size_t dot = name.find('.');
    const Effect* e = find_effect(name.substr(0, dot));
    if (!everywhere || e == nullptr) continue;
    const int p = find_param(*e, name.substr(dot + 1));
    if (p < 0) continue;
    if (extra.find(e) == extra.end()) order.push_back(e);
    extra[e].push_back(p);
  }
  for (const Effect* e : order) {
    std::vector<int>& params = extra[e];
    std::sort(params.begin(), params.end());
    d.add_candidate(ModelTerm{e, params});
  }
  return d;
}

/// The residual with only each run's constants fitted ("before": every model column
/// moved to its neutral value, linearised).
StepSolution raw_solution(const std::vector<RunStatistics>& runs, const RunsByLog& logs, const GroupFloors& floors) {
  return solve_step(assemble(Design(ModelSpec{}, {}, {}), runs, logs).all, floors);
}

std::vector<SignalResidual> merged_signals(const MergedStatistics& stats, const StepSolution& s, const StepSolution& raw,
                                           const GroupFloors& floors, const std::vector<int>& cols,
                                           const std::vector<RunStatistics>& runs) {
  const auto& names = kGroupSignals;
  std::vector<SignalResidual> out;
  for (int g = 0; g < kGroups; ++g) {
    const double f = floors.of(static_cast<Group>(g));
    if (!(f > 0.0) || s.n[g] == 0) continue;
    SignalResidual r;
    r.signal = names[static_cast<std::size_t>(g)];
    r.rms = rms(s.rss[g], s.n[g]);
    r.floor = f;
    r.raw_rms = raw.ok ? rms(raw.rss[g], raw.n[g]) : kNaN;
    r.held_back_rms = held_back_rms(stats.fold_a, stats.fold_b, floors, cols, static_cast<Group>(g));
    // The outliers stay out of the statistics; what they carried at each run's fit is kept.
    double rss_out = 0.0;
    std::int64_t rows_out = 0;
    for (const RunStatistics& run : runs) {
      rss_out += run.outlier_rss[static_cast<std::size_t>(g)];
      rows_out += run.outlier_rows[static_cast<std::size_t>(g)];
    }
    r.rms_with_outliers = rms(s.rss[g] + rss_out, s.n[g] + rows_out);
    r.rows = s.n[g];
    r.rows_with_outliers = s.n[g] + rows_out;
    out.push_back(r);
  }
  return out;
}

/// The model's nonlinear effects that some run has only as a candidate (columns at
/// zero): their merged value is one linearised step from there, and the residual the
/// statistics give for it leaves out the step's second-order terms (a 1 % quadrature
/// fitted so is 2.5 % off and the residual above its floor), so it cannot say "explained".
std::vector<std::string> linearised_from_zero(const Design& d, const std::vector<RunStatistics>& runs) {
  const std::vector<std::string> names = d.column_names();
  std::vector<std::string> out;
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    const DesignTerm& t = d.terms()[i];
    bool nonlinear = t.effect->envelope_only() || t.effect->shapes_basis();
    for (int p : t.params) nonlinear = nonlinear || t.effect->params()[static_cast<std::size_t>(p)].nonlinear;
    if (t.candidate || !nonlinear) continue;
    const auto candidate_in = [&](const RunStatistics& r) {
      for (int c : term_columns(d, i)) {
        const int at = column_index(r.columns, names[static_cast<std::size_t>(c)]);
        if (at >= r.nuisance_columns + r.model_columns) return true;
      }
      return false;
    };
    if (std::any_of(runs.begin(), runs.end(), candidate_in)) out.emplace_back(t.effect->name());
  }
  return out;
}

/// One candidate scored from the merged statistics: `asked` (a subset of candidate term
/// `i`'s parameters) with the model's columns; narrowed to the one parameter the merged
/// runs separate when the whole set is not (ranking.h solve_candidate, as explain).
void score_merged(const Design& d, std::size_t i, const ModelTerm& asked, const MergedStatistics& stats,
                  const StepSolution& base, const GroupFloors& floors, bool rd, const DiscoveryOptions& options,
                  MergedFit& out, std::map<std::string, std::vector<int>>& columns_of) {
  const DesignTerm& t = d.terms()[i];
  std::vector<int> set_cols;
  for (int p : asked.params) {
    const auto k = std::find(t.params.begin(), t.params.end(), p);
    if (k == t.params.end()) {
      out.not_evaluated.push_back(asked.reference() + ": not in every run's statistics");
      return;
    }
    set_cols.push_back(d.term_column(i) + static_cast<int>(k - t.params.begin()));
  }
  ModelTerm set = asked;
  const StepSolution s = solve_candidate(stats.all, floors, model_columns(d), set_cols, set);
  if (!s.ok) {
    out.not_evaluated.push_back(set.reference() + ": not separable from the model with the merged runs");
    return;
  }
  const std::string reference = set.reference();
  if (already_listed(out.candidates, reference)) return;
  std::vector<int>& own = columns_of[reference];  // narrowed: only the parameters kept
  for (std::size_t k = 0; k < asked.params.size(); ++k) {
    if (std::find(set.params.begin(), set.params.end(), asked.params[k]) != set.params.end()) own.push_back(set_cols[k]);
  }
  Candidate c;
  c.effect = reference;
  c.family = is_family(set);
  score_candidate(c, s, rd, base, floors, options);
  c.params = term_params(d, i, s, true);
  std::erase_if(c.params, [&](const ModelParameter& pv) {
    for (std::size_t k = 0; k < set.params.size(); ++k) {
      if (pv.name == set.param_name(k)) return false;
    }
    return true;
  });
  c.reason = reason_of(set, c.params);
  out.candidates.push_back(std::move(c));
}

/// Every candidate term of `d` (after the model's) scored against `base`: an effect's
/// sets as the reference run's fit asked for them (RunStatistics::candidate_sets), else
/// its whole term. What the runs' motion together lacks for candidates (motion_missing):
/// every run's speeds and reversals, and a log's between its chunks. `columns_of`: each
/// scored candidate's columns (the pair screen's, ranking.h screen_pairs).
void rank_merged(const Design& d, const MergedStatistics& stats, const StepSolution& base, const GroupFloors& floors,
                 const std::vector<RunStatistics>& runs, const RunsByLog& logs, std::size_t ref,
                 const DiscoveryOptions& options, MergedFit& out, std::map<std::string, std::vector<int>>& columns_of) {
  MotionSummary motion;
  for (std::size_t r = 0; r < runs.size(); ++r) add_motion(motion, runs[r].motion, r == 0);
  // A log's chunks share its reference zero: a log that went both ways, one direction per
  // chunk, reversed at a chunk boundary (a play is then no constant of the merge).
  for (const std::vector<std::size_t>& members : logs) {
    std::int64_t forward = 0, backward = 0, reversals = 0;
    for (const std::size_t r : members) {
      forward += runs[r].motion.forward;
      backward += runs[r].motion.backward;
      reversals += runs[r].motion.reversals;
    }
    if (members.size() > 1 && forward > 0 && backward > 0 && reversals == 0) ++motion.reversals;
  }
  const bool rd = runs.front().layout.rd;
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    if (!d.terms()[i].candidate) continue;
    const ModelTerm term{d.terms()[i].effect, d.terms()[i].params};
    if (const std::string missing = motion_missing(*term.effect, motion, runs.front().layout.sincos && rd); !missing.empty()) {
      out.not_evaluated.push_back(term.reference() + ": not identifiable in these runs: " + missing);
      continue;
    }
    bool by_sets = false;
    for (const std::string& name : runs[ref].candidate_sets) {
      const ModelSpec one = ModelSpec::parse(std::vector<std::string>{name}, options.customs);
      if (one.terms.front().effect != term.effect) continue;
      by_sets = true;
      score_merged(d, i, one.terms.front(), stats, base, floors, rd, options, out, columns_of);
    }
    if (!by_sets) score_merged(d, i, term, stats, base, floors, rd, options, out, columns_of);
  }
  order_ranked(out.candidates, options);
}

/// How far the runs' own fits of the nonlinear parameters lie from the merged value,
/// in the merged standard errors: the merge is exact to second order in this. Runs
/// relinearised at an earlier merge (RunStatistics::at_merged) have no note here: the
/// passes say how far their last step went (stats_run.h relinearise_merge).
std::string nonlinear_note(const Design& d, const std::vector<RunStatistics>& runs, const StepSolution& s,
                           const Eigen::VectorXd& z0) {
  if (std::any_of(runs.begin(), runs.end(), [](const RunStatistics& r) { return r.at_merged; })) return "";
  const double s2 = s.rss_w / std::max(1.0, static_cast<double>(s.n[0] + s.n[1] + s.n[2] - s.k));
  const std::vector<std::string> names = d.column_names();
  double widest = 0.0;
  std::string which;
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    const DesignTerm& t = d.terms()[i];
    if (t.candidate) continue;
    for (std::size_t k = 0; k < t.params.size(); ++k) {
      if (!t.effect->params()[static_cast<std::size_t>(t.params[k])].nonlinear) continue;
      const int col = d.term_column(i) + static_cast<int>(k);
      const double se = std::sqrt(std::max(0.0, s2 * s.inverse(col, col)));
      for (const RunStatistics& r : runs) {
        const int at = column_index(r.columns, names[static_cast<std::size_t>(col)]);
        if (at < 0 || !(se > 0.0)) continue;
        const double z = std::abs(r.point[at] - (z0[col] + s.dz[col])) / se;
        if (z > widest) {
          widest = z;
          which = names[static_cast<std::size_t>(col)];
        }
      }
    }
  }
  if (which.empty()) return "";
  return fmt::format("nonlinear parameters are merged from each run's fit linearised at its own solution: exact to "
                     "second order in how far those lie apart (the farthest, {}, {:.3g} standard errors from the merged "
                     "value{})",
                     which, widest, widest > 3.0 ? "; fit the logs together (resolver-model fit A.log B.log) to iterate" : "");
}

/// The outlier rows of the run's fit per group, and what they carry at its solution.
void take_outliers(const ModelFit& fit, RunStatistics& out) {
  for (const OutlierSignal& o : fit.outliers) out.outlier_samples += o.count;
  const auto& names = kGroupSignals;
  for (const SignalResidual& r : fit.signals) {
    for (int g = 0; g < kGroups; ++g) {
      // Without an R/D angle the fit's "position_error" is the sin/cos angle's, not group 0.
      if (r.signal != names[static_cast<std::size_t>(g)] || (g == 0 && !out.layout.rd)) continue;
      const auto gi = static_cast<std::size_t>(g);
      out.outlier_rows[gi] = std::max<std::int64_t>(0, r.rows_with_outliers - r.rows);
      out.outlier_rss[gi] = std::max(0.0, r.rms_with_outliers * r.rms_with_outliers * static_cast<double>(r.rows_with_outliers) -
                                              r.rms * r.rms * static_cast<double>(r.rows));
    }
  }
}

/// The run's fit of `effects`, or, where its rows cannot separate them and some are in
/// options.start.held, the fit of the others (`held` gets the rest).
ModelFit fit_or_hold(const PreparedLog& log, std::span<const std::string> effects, const DiscoveryOptions& options,
                     std::vector<std::string>& held) {
  try {
    return fit_prepared(log, effects, options);
  } catch (const std::invalid_argument&) {
    const std::vector<std::string>& holdable = options.start.held;
    std::vector<std::string> free;
    for (const std::string& e : effects) {
      (std::find(holdable.begin(), holdable.end(), e) != holdable.end() ? held : free).push_back(e);
    }
    if (held.empty()) throw;
    return fit_prepared(log, free, options);
  }
}

/// Passes over a run's rows that fit its frame shift at a point it was not fitted at
/// (fit_frame_shift: a shift turns by the model's mean angle error, a few mrad; two or
/// three passes settle it to 1e-7 rad).
constexpr int kFramePasses = 4;

/// The point the run's statistics are taken at: its fitted model, with the `held` effects
/// added at their start values; with options.start.at_start every parameter at its start
/// value (the merged fit). Off its own fit the run's frame shift is fitted again there
/// (its reference zero at those values), from the fit's frame.
Model statistics_point(const ModelFit& fit, const PreparedLog& log, const std::vector<std::string>& held,
                       const DiscoveryOptions& options) {
  if (held.empty() && !options.start.at_start) return fit.model;
  ModelSpec spec = fit.model.spec();
  for (const ModelTerm& t : ModelSpec::parse(held, options.customs).terms) spec.add(t);
  Model at(spec, log.p_r, log.p);
  for (const ModelParameter& p : fit.model.parameters()) at.set(p.name, p.value);
  (void)apply_start_values(options.start, at);
  Design d = design_for(at, log);  // the fit's frame, which a new Model does not have
  const std::vector<double>& shifts = fit.model.frame_shifts();
  for (int part = 0; part < d.parts(); ++part) d.set_frame_shift(part, shifts[static_cast<std::size_t>(part)]);
  (void)fit_frame_shift(d, log.rows, log.floors.floors(), kFramePasses);
  at.take_values(d);
  return at;
}

/// [floors] How far the merged fit lies from the runs' own points, as the RMS change of a
/// run's fitted signals over its rows (each group over the pooled floor): sqrt(d' M_r d /
/// n_r), d the merged values of the model's columns minus the run's (MergedFit::run_move).
double farthest_run_move(const Design& d, const std::vector<RunStatistics>& runs, const StepSolution& s,
                         const Eigen::VectorXd& z0, const GroupFloors& floors) {
  const std::vector<std::string> names = d.column_names();
  const std::vector<int> cols = model_columns(d);
  double widest = 0.0;
  for (const RunStatistics& r : runs) {
    std::vector<int> at;
    Eigen::VectorXd move(static_cast<Eigen::Index>(cols.size()));
    for (int c : cols) {
      if (c < d.nuisance_columns()) continue;  // the run's own constants are profiled, not moved
      const int k = column_index(r.columns, names[static_cast<std::size_t>(c)]);
      if (k < 0) continue;
      move[static_cast<Eigen::Index>(at.size())] = z0[c] + s.dz[c] - r.point[k];
      at.push_back(k);
    }
    const auto n = static_cast<Eigen::Index>(at.size());
    double q = 0.0;
    for (int g = 0; g < kGroups; ++g) {
      const double f = floors.of(static_cast<Group>(g));
      const NormalEquations& ne = r.stats.all[static_cast<std::size_t>(g)];
      if (!(f > 0.0) || ne.n() == 0) continue;
      for (Eigen::Index i = 0; i < n; ++i) {
        for (Eigen::Index j = 0; j < n; ++j) q += move[i] * ne.m()(at[static_cast<std::size_t>(i)], at[static_cast<std::size_t>(j)]) * move[j] / (f * f);
      }
    }
    if (r.fitted_rows > 0) widest = std::max(widest, std::sqrt(q / static_cast<double>(r.fitted_rows)));
  }
  return widest;
}

/// What the runs say of themselves: the effects some held (RunStatistics::held), and
/// faulty signals (never explained then).
void take_run_flags(const std::vector<RunStatistics>& runs, const std::vector<std::string>& names, MergedFit& out) {
  for (std::size_t r = 0; r < runs.size(); ++r) {
    for (const std::string& h : runs[r].held) {
      if (std::find(out.held.begin(), out.held.end(), h) == out.held.end()) out.held.push_back(h);
    }
    for (const std::string& u : runs[r].untrusted) {
      out.explained = false;
      out.untrusted = true;
      out.notes.push_back(fmt::format("{}: signal health: {} (a fit on faulty signals is no evidence: not explained)",
                                      names[r], u));
    }
  }
}

}  // namespace

RunStatistics run_statistics(const PreparedLog& log, std::span<const std::string> effects,
                             const DiscoveryOptions& options) {
  RunStatistics out;
  const ModelFit fit = fit_or_hold(log, effects, options, out.held);
  out.layout = pool_layout(log);
  out.params = fit.params;
  const Model model = statistics_point(fit, log, out.held, options);
  out.at_merged = options.start.at_start;
  out.effects = model.spec().references();
  out.values = model.values();
  Design d = design_for(model, log);
  out.frame_shift = d.frame_shift(0);
  out.nuisance_columns = d.nuisance_columns();
  out.model_columns = d.columns() - d.nuisance_columns();
  if (options.statistics_candidates) add_candidate_columns(d, fit, log, options, out.candidate_sets);
  out.columns = d.column_names();
  out.point = d.z();
  out.stats = PassStatistics(d.columns());
  accumulate(d, log.rows, log.floors.floors(), out.stats);
  out.floors = log.floors;
  out.fitted_rows = log.fitted_rows();
  out.samples = log.samples_in;
  out.span_s = log.motion.span_s;
  out.electrical_revolutions = log.electrical_revolutions();
  out.motion = log.motion;
  out.notes = fit.notes;
  for (const std::string& h : out.held) {
    out.notes.push_back(h + " held at its start value: this run's rows alone cannot separate it (the merge steps it)");
  }
  out.untrusted = options.untrusted_input;
  take_outliers(fit, out);
  return out;
}

MergedFit merge_runs(const std::vector<RunStatistics>& runs, const std::vector<std::string>& names,
                     std::span<const std::string> effects, const DiscoveryOptions& options, std::span<const int> log_of,
                     double lambda) {
  if (runs.empty()) throw std::invalid_argument("nothing to merge: no statistics given");
  if (names.size() != runs.size()) throw std::invalid_argument("merge: one name per run");
  for (std::size_t r = 1; r < runs.size(); ++r) {
    check_same_layout(runs.front().layout, runs[r].layout, names.front(), names[r]);
  }
  const std::size_t ref = reference_run(runs, names);
  MergedFit out;
  out.runs = static_cast<int>(runs.size());
  out.effects = effects.empty() ? runs[ref].effects : std::vector<std::string>(effects.begin(), effects.end());
  const ModelSpec spec = ModelSpec::parse(out.effects, options.customs);
  const Design d = merged_design(spec, runs, ref, options);
  const std::vector<std::string> columns = d.column_names();
  for (std::size_t r = 0; r < runs.size(); ++r) {
    for (int c = 0; c < d.columns(); ++c) {
      if (column_index(runs[r].columns, columns[static_cast<std::size_t>(c)]) >= 0) continue;
      throw std::invalid_argument(fmt::format("{} has no column {} (its model: {}; its candidates are the catalog "
                                              "effects its signals allow): make its statistics with --effects {}",
                                              names[r], columns[static_cast<std::size_t>(c)],
                                              fmt::join(runs[r].effects, ","), fmt::join(out.effects, ",")));
    }
  }
  std::vector<const FloorReport*> floors;
  std::vector<double> rows;
  for (const RunStatistics& r : runs) {
    floors.push_back(&r.floors);
    rows.push_back(static_cast<double>(r.fitted_rows));
    out.rows += r.fitted_rows;
  }
  out.floors = pool_floor_reports(floors, rows);
  const GroupFloors gf = out.floors.floors();
  const Eigen::VectorXd z0 = d.z();
  const RunsByLog logs = runs_by_log(runs.size(), log_of);
  const MergedStatistics stats = assemble(d, runs, logs);
  const std::vector<int> cols = model_columns(d);
  const StepSolution s = solve_step(stats.all, gf, cols, lambda);
  // The merged statistics have the runs' constants profiled out already (merged_statistics.h).
  out.cost_at_point = weighted_yy(stats.all, gf);
  out.run_move = farthest_run_move(d, runs, s, z0, gf);
  if (!s.ok) {
    throw std::invalid_argument(fmt::format("the model's effects ({}) are not separable with the merged runs' signals",
                                            fmt::join(out.effects, ", ")));
  }
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    if (d.terms()[i].candidate) continue;
    for (ModelParameter& p : term_params(d, i, s, true)) out.params.push_back(std::move(p));
  }
  out.rd = runs.front().layout.rd;
  out.bic = bic_of(s);
  out.weighted_rss = s.rss_w;
  out.nuisance = constants_at(d, s, runs, names, logs);
  out.signals = merged_signals(stats, s, raw_solution(runs, logs, gf), gf, cols, runs);
  for (const RunStatistics& r : runs) out.outlier_samples += r.outlier_samples;
  out.explained = !out.signals.empty();
  for (const SignalResidual& r : out.signals) {
    if (r.rms > options.explained_ratio * r.floor) out.explained = false;
    if (std::isfinite(r.held_back_rms) && r.held_back_rms > options.explained_ratio * r.floor) out.explained = false;
    // As explain: impulsive samples that carry a signal above its floor are no explanation.
    if (out.outlier_samples > 0 && r.rms_with_outliers > options.explained_ratio * r.floor) out.explained = false;
  }
  out.linearised = linearised_from_zero(d, runs);
  if (const std::vector<std::string>& stepped = out.linearised; !stepped.empty()) {
    out.explained = false;
    out.notes.push_back(fmt::format("{} {} only a candidate in some run's statistics: fitted here by one linearised "
                                    "step from zero, so the residual is not evaluated at the value and the merge "
                                    "does not say explained; make the statistics with it in --effects",
                                    fmt::join(stepped, ", "), stepped.size() == 1 ? "is" : "are"));
  }
  take_run_flags(runs, names, out);
  std::map<std::string, std::vector<int>> columns_of;
  rank_merged(d, stats, s, gf, runs, logs, ref, options, out, columns_of);
  for (Candidate& c : out.candidates) flag_one_step(c, options);
  if (out.explained || out.untrusted || !out.linearised.empty()) {
    // As explain: a model at the floor needs nothing; a candidate's BIC drop there is noise
    // fitted (with formal errors on 10^5 rows a few thousandths of the residual). Fitted
    // to faulty signals a candidate names the fault's shape, not the resolver's physics.
    for (Candidate& c : out.candidates) c.proposed = false;
  }
  out.screened_pairs = screen_pairs(out.candidates, columns_of, stats.all, gf, cols);
  if (runs.size() > 1) {
    ModelFit merged;
    merged.params = out.params;
    std::vector<ModelFit> alone(runs.size());
    for (std::size_t r = 0; r < runs.size(); ++r) alone[r].params = runs[r].params;
    out.comparisons = compare_with_pool(merged, alone, names);
    for (std::string& n : disagreement_notes(out.comparisons)) out.notes.push_back(std::move(n));
  }
  out.notes.emplace_back("standard errors are formal (the merged residual variance): statistics keep no "
                         "revolution-to-revolution spread");
  out.nonlinear = !strictly_linear(d);
  if (d.nonlinear()) {
    if (std::string n = nonlinear_note(d, runs, s, z0); !n.empty()) out.notes.push_back(std::move(n));
  }
  return out;
}

std::vector<std::string> candidates_to_refit(const MergedFit& m, const DiscoveryOptions& options) {
  if (m.explained || m.untrusted || !m.linearised.empty()) return {};
  std::vector<std::string> out = exact_refits(m.candidates, options);
  std::erase_if(out, [&](const std::string& e) {
    return std::none_of(m.candidates.begin(), m.candidates.end(), [&](const Candidate& c) { return c.effect == e && c.stepped; });
  });
  return out;
}

void take_exact_refit(MergedFit& m, const std::string& effect, const MergedFit& with, const DiscoveryOptions& options) {
  const auto it = std::find_if(m.candidates.begin(), m.candidates.end(), [&](const Candidate& c) { return c.effect == effect; });
  if (it == m.candidates.end() || with.signals.empty()) return;
  Candidate& c = *it;
  const auto rms_of = [&](const char* signal) {
    for (const SignalResidual& r : with.signals) {
      if (r.signal == signal) return r.rms;
    }
    return kNaN;
  };
  // As score_candidate, from the merged exact fit instead of the linearised step.
  c.residual_after_rad = rms_of(m.rd ? "position_error" : "sin_cos");
  c.sincos_residual_after = rms_of("sin_cos");
  c.dq_residual_after = rms_of("i_dq");
  c.weighted_rss = with.weighted_rss;
  c.score = with.bic;
  c.bic_drop = m.bic - c.score;
  c.err = m.weighted_rss > 0.0 ? (m.weighted_rss - with.weighted_rss) / m.weighted_rss : 0.0;
  c.proposed = c.bic_drop > options.proposal_bic_drop;
  c.reaches_floor = std::all_of(with.signals.begin(), with.signals.end(), [&](const SignalResidual& r) {
    return r.rms <= options.explained_ratio * r.floor;
  });
  const ModelSpec one = ModelSpec::parse(std::vector<std::string>{effect}, options.customs);
  const ModelTerm& term = one.terms.front();
  c.params.clear();
  for (std::size_t k = 0; k < term.params.size(); ++k) {
    for (const ModelParameter& q : with.params) {
      if (q.name == term.param_name(k)) c.params.push_back(q);
    }
  }
  c.reason = reason_of(term, c.params);
  c.refitted = true;
  c.stepped = false;
  m.refitted.push_back(effect);
  if (std::find(with.held.begin(), with.held.end(), effect) != with.held.end()) m.held.push_back(effect);
  order_ranked(m.candidates, options);
}

}  // namespace resolver
