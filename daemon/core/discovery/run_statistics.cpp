#include "daemon/core/discovery/run_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/discovery/fit_support.h"
#include "daemon/core/discovery/pool.h"
#include "daemon/core/discovery/ranking.h"
#include "daemon/core/effects/registry.h"

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A candidate the run's layout allows: the model lacks it, and the signals it needs are there.
bool candidate_for(const Effect& e, const ModelSpec& spec, const PreparedLog& log) {
  if (!e.fittable() || spec.find(e) != nullptr) return false;
  if (e.needs_reference() && !log.reference) return false;
  if (e.needs_aligned_reference() && !log.reference_aligned) return false;
  return !(e.current_side() && !log.currents);
}

/// Position of `name` in `names`, or -1.
int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

PoolLayout layout_of(const RunStatistics& r) {
  return {r.p_r, r.p, r.reference, r.reference_aligned, r.rd, r.sincos, r.currents};
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

/// The merged design: `spec` at the reference run's values, each run one part with
/// its frame shift, then every candidate column all runs have.
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
  PreparedLog layout;
  layout.rd = runs[ref].rd;
  layout.sincos = runs[ref].sincos;
  layout.currents = runs[ref].currents;
  layout.reference = runs[ref].reference;
  layout.reference_aligned = runs[ref].reference_aligned;
  Design d(spec, values, nuisances_for(layout));
  d.set_parts(static_cast<int>(runs.size()));
  for (std::size_t r = 0; r < runs.size(); ++r) d.set_frame_shift(static_cast<int>(r), runs[r].frame_shift);
  // Candidates: the columns every run has that the model does not, grouped by effect.
  const std::vector<std::string> have = d.column_names();
  std::map<const Effect*, std::vector<int>> extra;
  std::vector<const Effect*> order;
  for (int c = runs[ref].nuisance_columns; c < static_cast<int>(runs[ref].columns.size()); ++c) {
    const std::string& name = runs[ref].columns[static_cast<std::size_t>(c)];
    if (index_of(have, name) >= 0) continue;
    const bool everywhere = std::all_of(runs.begin(), runs.end(), [&](const RunStatistics& r) { return index_of(r.columns, name) >= 0; });
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

/// Adds run `r` (part `part` of `d`) to `into`, moved from its point to the design's:
/// b + M d and yy + 2 d'b + d'M d (header). Columns the design lacks are held at
/// their neutral value.
void add_run(const RunStatistics& run, int part, const Design& d, const Eigen::VectorXd& z0, PassStatistics& into) {
  const std::vector<std::string> names = d.column_names();
  const auto k = static_cast<Eigen::Index>(run.columns.size());
  std::vector<int> to(static_cast<std::size_t>(k), -1);
  Eigen::VectorXd shift = run.point;  // z_r - target: the target is 0 unless the design has the column
  for (Eigen::Index c = 0; c < k; ++c) {
    if (c < run.nuisance_columns) {
      to[static_cast<std::size_t>(c)] = d.nuisance_column(part, static_cast<std::size_t>(c));
      shift[c] = 0.0;
      continue;
    }
    const int at = index_of(names, run.columns[static_cast<std::size_t>(c)]);
    if (at < d.nuisance_columns()) continue;  // not in the design: held at neutral
    to[static_cast<std::size_t>(c)] = at;
    shift[c] = run.point[c] - z0[at];
  }
  const auto add = [&](const NormalEquations& from, NormalEquations& out) {
    const Eigen::VectorXd b = from.b() + from.m() * shift;
    const double yy = from.yy() + 2.0 * shift.dot(from.b()) + shift.dot(from.m() * shift);
    Eigen::MatrixXd m = out.m();
    Eigen::VectorXd bo = out.b();
    for (Eigen::Index i = 0; i < k; ++i) {
      const int ti = to[static_cast<std::size_t>(i)];
      if (ti < 0) continue;
      bo[ti] += b[i];
      for (Eigen::Index j = 0; j < k; ++j) {
        const int tj = to[static_cast<std::size_t>(j)];
        if (tj >= 0) m(ti, tj) += from.m()(i, j);
      }
    }
    out.set(std::move(m), std::move(bo), out.yy() + std::max(0.0, yy), out.n() + from.n());
  };
  for (std::size_t g = 0; g < static_cast<std::size_t>(kGroups); ++g) {
    add(run.stats.all[g], into.all[g]);
    add(run.stats.fold_a[g], into.fold_a[g]);
  }
}

/// Each run's nuisance constants at the solution, named "...[run]".
std::vector<ModelParameter> nuisances_of(const Design& d, const StepSolution& s, const std::vector<std::string>& names) {
  std::vector<ModelParameter> out;
  for (int part = 0; part < d.parts(); ++part) {
    for (std::size_t j = 0; j < d.nuisances().size(); ++j) {
      double v = s.dz[d.nuisance_column(part, j)];
      const Nuisance n = d.nuisances()[j];
      if (n == Nuisance::kRdConstant || n == Nuisance::kSaConstant) v -= d.frame_shift(part);
      out.push_back({std::string(nuisance_name(n)) + "[" + names[static_cast<std::size_t>(part)] + "]", v, kNaN, ""});
    }
  }
  return out;
}

/// Every run moved to the point of `d` and added (add_run).
PassStatistics assemble(const Design& d, const std::vector<RunStatistics>& runs) {
  const Eigen::VectorXd z0 = d.z();
  PassStatistics stats(d.columns());
  for (std::size_t r = 0; r < runs.size(); ++r) add_run(runs[r], static_cast<int>(r), d, z0, stats);
  return stats;
}

/// The residual with only each run's constants fitted ("before": every model column
/// moved to its neutral value, linearised).
StepSolution raw_solution(const Design& d, const std::vector<RunStatistics>& runs, const GroupFloors& floors) {
  Design none(ModelSpec{}, {}, d.nuisances());
  none.set_parts(d.parts());
  return solve_step(assemble(none, runs).all, floors);
}

std::vector<SignalResidual> merged_signals(const PassStatistics& stats, const StepSolution& s, const StepSolution& raw,
                                           const GroupFloors& floors, const std::vector<int>& cols) {
  const char* names[kGroups] = {"position_error", "sin_cos", "i_dq"};
  std::vector<SignalResidual> out;
  for (int g = 0; g < kGroups; ++g) {
    const double f = floors.of(static_cast<Group>(g));
    if (!(f > 0.0) || s.n[g] == 0) continue;
    SignalResidual r;
    r.signal = names[g];
    r.rms = rms(s.rss[g], s.n[g]);
    r.floor = f;
    r.raw_rms = raw.ok ? rms(raw.rss[g], raw.n[g]) : kNaN;
    r.held_back_rms = held_back_rms(stats, floors, cols, static_cast<Group>(g));
    r.rms_with_outliers = r.rms;  // outliers stay out of the statistics
    r.rows = s.n[g];
    out.push_back(r);
  }
  return out;
}

/// Every candidate term of `d` (after the model's) scored against `base`.
/// What the runs' motion together lacks for candidates (motion_missing): every run's
/// speeds and reversals.
void rank_merged(const Design& d, const PassStatistics& stats, const StepSolution& base, const GroupFloors& floors,
                 const std::vector<RunStatistics>& runs, const DiscoveryOptions& options, MergedFit& out) {
  MotionSummary motion;
  for (std::size_t r = 0; r < runs.size(); ++r) add_motion(motion, runs[r].motion, r == 0);
  const bool rd = runs.front().rd;
  const std::vector<int> base_cols = model_columns(d);
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    if (!d.terms()[i].candidate) continue;
    std::vector<int> cols = base_cols;
    for (int c : term_columns(d, i)) cols.push_back(c);
    const ModelTerm term{d.terms()[i].effect, d.terms()[i].params};
    if (const std::string missing = motion_missing(*term.effect, motion, runs.front().sincos && rd); !missing.empty()) {
      out.not_evaluated.push_back(term.reference() + ": not identifiable in these runs: " + missing);
      continue;
    }
    const StepSolution s = solve_step(stats.all, floors, cols);
    if (!s.ok) {
      out.not_evaluated.push_back(term.reference() + ": not separable from the model with the merged runs");
      continue;
    }
    Candidate c;
    c.effect = term.reference();
    score_candidate(c, s, rd, base, floors, options);
    c.params = term_params(d, i, s, true);
    c.reason = reason_of(term, c.params);
    out.candidates.push_back(std::move(c));
  }
  std::sort(out.candidates.begin(), out.candidates.end(), [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
}

/// How far the runs' own fits of the nonlinear parameters lie from the merged value,
/// in the merged standard errors: the merge is exact to second order in this.
std::string nonlinear_note(const Design& d, const std::vector<RunStatistics>& runs, const StepSolution& s,
                           const Eigen::VectorXd& z0) {
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
        const int at = index_of(r.columns, names[static_cast<std::size_t>(col)]);
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

}  // namespace

RunStatistics run_statistics(const PreparedLog& log, std::span<const std::string> effects,
                             const DiscoveryOptions& options) {
  const ModelFit fit = fit_prepared(log, effects, options);
  RunStatistics out;
  out.p_r = log.p_r;
  out.p = log.p;
  out.reference = log.reference;
  out.reference_aligned = log.reference_aligned;
  out.rd = log.rd;
  out.sincos = log.sincos;
  out.currents = log.currents;
  out.effects = fit.model.spec().references();
  out.params = fit.params;
  out.values = fit.model.values();
  Design d = design_for(fit.model, log);
  out.frame_shift = d.frame_shift(0);
  out.nuisance_columns = d.nuisance_columns();
  out.model_columns = d.columns() - d.nuisance_columns();
  for (const Effect* e : effect_registry()) {
    if (candidate_for(*e, fit.model.spec(), log)) d.add_candidate(ModelTerm{e, default_params(*e)});
  }
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
  out.untrusted = options.untrusted_input;
  return out;
}

MergedFit merge_runs(const std::vector<RunStatistics>& runs, const std::vector<std::string>& names,
                     std::span<const std::string> effects, const DiscoveryOptions& options) {
  if (runs.empty()) throw std::invalid_argument("nothing to merge: no statistics given");
  if (names.size() != runs.size()) throw std::invalid_argument("merge: one name per run");
  for (std::size_t r = 1; r < runs.size(); ++r) {
    check_same_layout(layout_of(runs.front()), layout_of(runs[r]), names.front(), names[r]);
  }
  const std::size_t ref = reference_run(runs, names);
  MergedFit out;
  out.runs = static_cast<int>(runs.size());
  out.effects = effects.empty() ? runs[ref].effects : std::vector<std::string>(effects.begin(), effects.end());
  const ModelSpec spec = ModelSpec::parse(out.effects, options.customs);
  const Design d = merged_design(spec, runs, ref, options);
  const std::vector<std::string> columns = d.column_names();
  for (std::size_t r = 0; r < runs.size(); ++r) {
    for (int c = d.nuisance_columns(); c < d.columns(); ++c) {
      if (index_of(runs[r].columns, columns[static_cast<std::size_t>(c)]) >= 0) continue;
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
  const PassStatistics stats = assemble(d, runs);
  const std::vector<int> cols = model_columns(d);
  const StepSolution s = solve_step(stats.all, gf, cols);
  if (!s.ok) {
    throw std::invalid_argument(fmt::format("the model's effects ({}) are not separable with the merged runs' signals",
                                            fmt::join(out.effects, ", ")));
  }
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    if (d.terms()[i].candidate) continue;
    for (ModelParameter& p : term_params(d, i, s, true)) out.params.push_back(std::move(p));
  }
  out.nuisance = nuisances_of(d, s, names);
  out.signals = merged_signals(stats, s, raw_solution(d, runs, gf), gf, cols);
  out.explained = !out.signals.empty();
  for (const SignalResidual& r : out.signals) {
    if (r.rms > options.explained_ratio * r.floor) out.explained = false;
    if (std::isfinite(r.held_back_rms) && r.held_back_rms > options.explained_ratio * r.floor) out.explained = false;
  }
  for (std::size_t r = 0; r < runs.size(); ++r) {
    for (const std::string& u : runs[r].untrusted) {
      out.explained = false;
      out.notes.push_back(fmt::format("{}: signal health: {} (a fit on faulty signals is no evidence: not explained)",
                                      names[r], u));
    }
  }
  rank_merged(d, stats, s, gf, runs, options, out);
  if (runs.size() > 1) {
    ModelFit merged;
    merged.params = out.params;
    std::vector<ModelFit> alone(runs.size());
    for (std::size_t r = 0; r < runs.size(); ++r) alone[r].params = runs[r].params;
    out.comparisons = compare_with_pool(merged, alone, names);
    for (std::string& n : disagreement_notes(out.comparisons)) out.notes.push_back(std::move(n));
  }
  out.notes.push_back("standard errors are formal (the merged residual variance): statistics keep no "
                      "revolution-to-revolution spread");
  if (d.nonlinear()) {
    if (std::string n = nonlinear_note(d, runs, s, z0); !n.empty()) out.notes.push_back(std::move(n));
  }
  return out;
}

}  // namespace resolver
