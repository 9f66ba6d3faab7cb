#include "daemon/core/discovery/model_discovery.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/discovery/breakdowns.h"
#include "daemon/core/discovery/fit_support.h"
#include "daemon/core/discovery/narration.h"
#include "daemon/core/discovery/ranking.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/model/custom_effect.h"
#include "daemon/core/model/least_squares.h"

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Revolution blocks needed before standard errors come from their spread.
constexpr int kMinRobustBlocks = 8;
/// A candidate that does not reach the floor still counts as "the missing effect"
/// when it removes at least this share of the residual power above the floor.
constexpr double kExcessExplainedShare = 0.8;

SampleAccount account_of(const PreparedLog& log) {
  SampleAccount a;
  a.samples_in = log.samples_in;
  a.rows = static_cast<std::int64_t>(log.rows.size());
  a.fitted = log.fitted_rows();
  a.moving = log.motion.moving;
  a.standstill = log.motion.standstill;
  a.outliers = log.outlier_rows();
  a.excluded = std::count_if(log.rows.begin(), log.rows.end(), [](const FitRow& r) { return r.has(FitRow::kExcluded); });
  a.without_angle = log.without_angle;
  a.without_reference = log.without_reference;
  a.span_s = log.motion.span_s;
  a.revolutions_mechanical = log.motion.travelled / kTwoPi;
  a.revolutions_electrical = log.electrical_revolutions();
  a.reversals = log.motion.reversals;
  a.standstills = log.motion.standstills;
  a.fold_rule = log.fold_rule;
  return a;
}

/// Standard errors in value coordinates from an internal covariance.
void fill_params(ModelFit& f, const Design& d, const Eigen::MatrixXd& cov) {
  std::vector<double> ses;
  f.params.clear();
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    const DesignTerm& t = d.terms()[i];
    if (t.candidate) continue;
    const auto ps = t.effect->params();
    for (std::size_t k = 0; k < t.params.size(); ++k) {
      const auto p = static_cast<std::size_t>(t.params[k]);
      const int col = d.term_column(i) + static_cast<int>(k);
      double se = std::sqrt(std::max(0.0, cov(col, col)));
      if (ps[p].polar == Polar::kAmplitude || ps[p].polar == Polar::kPhase) {
        const int cx = ps[p].polar == Polar::kAmplitude ? col : col - 1;
        se = polar_std_error(t, p, cov.block(cx, cx, 2, 2));
      } else if (ps[p].nonlinear && ps[p].scale == FitScale::kInverseSquare) {
        const double z = to_internal(ps[p], t.values[p]);
        se = z > 0.0 ? se * 0.5 * std::pow(z, -1.5) : kNaN;
      }
      ses.push_back(se);
      f.params.push_back({std::string(t.effect->name()) + "." + std::string(ps[p].name), t.values[p], se,
                          std::string(ps[p].unit)});
    }
  }
  f.model.set_standard_errors(ses);
}

/// Terms of the model whose every fitted parameter lies within 2 standard errors of its
/// neutral value (a phase aside: it has none), as one note; "" when none. A term the
/// user's loop added earlier that a later one made redundant (a mechanical 6th harmonic
/// standing in for the loop's 2 theta lag without sin/cos: 1.3e-8 +- 8.7e-8 rad once the
/// loop was in) otherwise sat in an "explained" model unremarked.
std::string unsupported_terms_note(const Design& d, const ModelFit& f) {
  constexpr double kSupportedFrom = 2.0;  // standard errors: 1 in 22 by chance
  std::vector<std::string> unsupported, values;
  std::size_t at = 0, model_term = 0;
  for (const DesignTerm& t : d.terms()) {
    if (t.candidate) continue;
    const auto ps = t.effect->params();
    bool supported = false, checked = false;
    std::vector<std::string> these;
    for (std::size_t k = 0; k < t.params.size(); ++k, ++at) {
      const ParamInfo& info = ps[static_cast<std::size_t>(t.params[k])];
      const ModelParameter& p = f.params[at];
      if (info.polar == Polar::kPhase) continue;
      if (!(std::isfinite(p.std_error) && p.std_error > 0.0)) supported = true;  // said elsewhere
      checked = true;
      if (std::abs(p.value - info.neutral) >= kSupportedFrom * p.std_error) supported = true;
      these.push_back(fmt::format("{} = {:.3g} +- {:.2g}", info.name, p.value, p.std_error));
    }
    if (checked && !supported) {
      unsupported.push_back(model_term < f.effects.size() ? f.effects[model_term] : std::string(t.effect->name()));
      values.push_back(fmt::format("{}", fmt::join(these, ", ")));
    }
    ++model_term;
  }
  if (unsupported.empty()) return {};
  return fmt::format("{} {} within {:g} standard errors of doing nothing ({}): this log does not support {}; the "
                     "model without {} may fit as well",
                     fmt::join(unsupported, ", "), unsupported.size() == 1 ? "is" : "are", kSupportedFrom,
                     fmt::join(values, "; "), unsupported.size() == 1 ? "it" : "them",
                     unsupported.size() == 1 ? "it" : "them");
}

/// A custom term that is inf or nan on most of this log's rows leaves its
/// coefficient nothing to fit: says so, naming the block and the term, instead of
/// "not separable". (A term inf or nan everywhere is refused at load, custom_effect.h.)
void throw_if_custom_term_not_finite(const std::vector<std::string>& effects, const PreparedLog& log,
                                     const DiscoveryOptions& options) {
  if (options.customs == nullptr || log.rows.empty()) return;
  for (const auto& e : options.customs->all()) {
    const std::string name(e->name());
    const bool used = std::any_of(effects.begin(), effects.end(),
                                  [&](const std::string& r) { return r == name || r.starts_with(name + "("); });
    if (!used) continue;
    for (std::size_t i = 0; i < e->term_count(); ++i) {
      std::size_t bad = 0;
      const FitRow* first = nullptr;
      double value = 0.0;
      for (const FitRow& r : log.rows) {
        const double v = e->term_value(i, r.sig);
        if (std::isfinite(v)) continue;
        if (bad++ == 0) {
          first = &r;
          value = v;
        }
      }
      if (2 * bad < log.rows.size()) continue;
      throw std::invalid_argument(fmt::format(
          "{} custom effect '{}', term {} \"{}\" is not finite on {} of this log's {} rows (e.g. {} at theta = {:.4g}, "
          "omega = {:.4g} rad/s, t = {:.4g} s): its coefficient has nothing to fit; a division by zero, or a function "
          "outside its domain for this motion",
          e->spec().origin, name, i + 1, e->spec().terms[i], bad, log.rows.size(),
          std::isnan(value) ? "nan" : (value > 0 ? "inf" : "-inf"), first->sig.theta, first->sig.omega, first->sig.t));
    }
  }
}

}  // namespace

std::string std_error_basis(const ModelFit& f) {
  if (f.robust_errors) {
    return fmt::format("robust: revolution-to-revolution spread of {} revolutions", f.error_revolutions);
  }
  return fmt::format("formal: residual variance ({} revolutions, the spread needs {})", f.error_revolutions,
                     kMinRobustBlocks);
}

bool removes_most_excess(const std::vector<SignalResidual>& signals, std::int64_t rows, bool rd,
                         double weighted_rss_after) {
  // Share of the weighted residual power above the floor the candidate removes
  // (a row at the floor weighs 1).
  double base = 0.0;
  for (const SignalResidual& r : signals) {
    if (r.signal == "position_error" && !rd) continue;
    base += static_cast<double>(r.rows) * (r.rms * r.rms) / (r.floor * r.floor);
  }
  const double excess = base - static_cast<double>(rows);
  const double after = weighted_rss_after - static_cast<double>(rows);
  return excess > 0.0 && (excess - after) >= kExcessExplainedShare * excess;
}

std::string_view to_string(Verdict v) {
  switch (v) {
    case Verdict::kExplained: return "explained";
    case Verdict::kMissingEffect: return "missing_effect";
    case Verdict::kUnexplained: return "unexplained";
  }
  return "?";
}

std::vector<std::string_view> fittable_effects() {
  std::vector<std::string_view> out;
  for (const Effect* e : effect_registry()) {
    if (e->fittable()) out.push_back(e->name());
  }
  return out;
}

namespace {

/// The nuisance constants at the solution (the last step solved them from zero),
/// into f.nuisance (a pooled fit's per log, named "[log]"); returned per part as the
/// residual pass measures about them.
std::vector<NuisanceValues> nuisance_at_solution(const Design& d, const FitResult& fr, const PreparedLog& log,
                                                 ModelFit& f) {
  std::vector<NuisanceValues> out(static_cast<std::size_t>(d.parts()));
  for (int part = 0; part < d.parts(); ++part) {
    NuisanceValues& nv = out[static_cast<std::size_t>(part)];
    const std::string suffix =
        log.part_names.empty() ? std::string() : "[" + log.part_names[static_cast<std::size_t>(part)] + "]";
    for (std::size_t j = 0; j < d.nuisances().size(); ++j) {
      const double v = fr.last.dz[d.nuisance_column(part, j)];
      // The position errors' constants: the prediction carries -frame_shift (design.h),
      // the solution what is left.
      double total = v;
      switch (d.nuisances()[j]) {
        case Nuisance::kRdConstant: nv.rd = v; total -= d.frame_shift(part); break;
        case Nuisance::kSaConstant: nv.sa = v; total -= d.frame_shift(part); break;
        case Nuisance::kScGain: nv.sr = v; break;
        case Nuisance::kIdConstant: nv.d = v; break;
        case Nuisance::kIqConstant: nv.q = v; break;
      }
      f.nuisance.push_back({std::string(nuisance_name(d.nuisances()[j])) + suffix, total, kNaN, ""});
    }
  }
  return out;
}

/// The parameters' covariance: from the revolution-to-revolution spread of the
/// scores when the log has enough revolutions (honest with correlated residuals),
/// else formal. Sets f.robust_errors.
Eigen::MatrixXd parameter_covariance(const StepSolution& s, const ResidualPass& pass, const std::vector<int>& cols,
                                     ModelFit& f) {
  const double dof = static_cast<double>(s.n[0] + s.n[1] + s.n[2] - s.k);
  Eigen::MatrixXd cov = s.inverse * (s.rss_w / std::max(dof, 1.0));
  f.error_revolutions = pass.blocks;
  if (pass.blocks < kMinRobustBlocks) return cov;
  const auto k = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd m_inv(k, k);
  for (Eigen::Index a = 0; a < k; ++a) {
    for (Eigen::Index b = 0; b < k; ++b) m_inv(a, b) = s.inverse(cols[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(b)]);
  }
  const double correction = static_cast<double>(pass.blocks) / (pass.blocks - 1.0);
  // robust = M^-1 S M^-1 with S = sum over blocks of g g' (positive semidefinite), formed
  // as F F' with F = M^-1 P' L sqrt(D) from S's LDLT: each variance is then a sum of
  // squares. Multiplied out, rounding lost a nonlinear parameter's variance: the
  // tracking loop's z = 1/omega_n^2 ~ 1e-7 beside alpha ~ 1e-2 gave a variance below
  // zero, printed as a standard error of 0 (tracking_loop.omega_n = 3047 +- 0).
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(pass.score_outer);
  const Eigen::VectorXd root_d = ldlt.vectorD().cwiseMax(0.0).cwiseSqrt();
  const Eigen::MatrixXd l_root = Eigen::MatrixXd(ldlt.matrixL()) * root_d.asDiagonal();
  const Eigen::MatrixXd factor = m_inv * (ldlt.transpositionsP().transpose() * l_root);
  const Eigen::MatrixXd robust = factor * factor.transpose() * correction;
  for (Eigen::Index a = 0; a < k; ++a) {
    for (Eigen::Index b = 0; b < k; ++b) {
      cov(cols[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(b)]) = robust(a, b);
    }
  }
  f.robust_errors = true;
  return cov;
}

/// Every fitted signal's residual against its floor, raw and held back, into
/// f.signals; a residual whose evaluated and linearised figures differ marks the
/// fit unconverged (the notes say which).
std::vector<std::string> signal_residuals(const PreparedLog& log, const FitResult& fr, const ResidualPass& pass,
                                          const StepSolution& raw, const GroupFloors& floors,
                                          const std::vector<int>& cols, ModelFit& f) {
  const auto& names = kGroupSignals;
  std::vector<std::string> convergence_notes;
  const double gf[kGroups] = {floors.rd, floors.sc, floors.cur};
  const StepSolution& s = fr.last;
  for (int g = 0; g < kGroups; ++g) {
    if (!(gf[g] > 0.0) || s.n[g] == 0) continue;
    SignalResidual r;
    r.signal = names[static_cast<std::size_t>(g)];
    // The residual with the prediction evaluated at the fitted values. The step's
    // own figure is linearised; where they differ the fit has not converged (a
    // nonlinear parameter at its bound, or out of passes) and the evaluated one is
    // what the data says.
    r.rms = rms(pass.rss[g], pass.n[g]);
    const double linearised = rms(s.rss[g], s.n[g]);
    if (std::abs(r.rms - linearised) > 0.01 * std::max(r.rms, gf[g])) {
      f.converged = false;
      convergence_notes.push_back(fmt::format("{}: the fit did not converge: evaluated residual {:.4g} against its linearised "
                                    "{:.4g} (a nonlinear parameter at its bound, or the passes ran out)",
                                    names[static_cast<std::size_t>(g)], r.rms, linearised));
    }
    r.floor = gf[g];
    r.raw_rms = rms(raw.rss[g], raw.n[g]);
    r.held_back_rms = held_back_rms(fr.stats, floors, cols, static_cast<Group>(g));
    r.rows = s.n[g];
    r.rms_with_outliers = rms(pass.rss_with_outliers[g], pass.n_with_outliers[g]);
    r.rows_with_outliers = pass.n_with_outliers[g];
    f.signals.push_back(r);
  }
  if (!log.rd && log.sincos) {
    // Without an R/D angle the position error is the sin/cos angle's.
    SignalResidual r;
    r.signal = "position_error";
    r.rms = rms(pass.rss_position, pass.n_position);
    r.floor = floors.sc;
    r.raw_rms = kNaN;
    r.held_back_rms = kNaN;
    r.rows = pass.n_position;
    f.signals.insert(f.signals.begin(), r);
  }
  return convergence_notes;
}

/// The residual pass's breakdowns as the fit reports them.
void take_breakdowns(const ResidualPass& pass, ModelFit& f) {
  f.rms_with_outliers_rad = rms(pass.rss_position_with_outliers, pass.n_position_with_outliers);
  f.harmonics = pass.harmonics;
  f.harmonics_mech = pass.harmonics_mech;
  f.harmonics_id = pass.harmonics_id;
  f.harmonics_iq = pass.harmonics_iq;
  f.speed_bins = pass.speed_bins;
  f.time_bins = pass.time_bins;
  f.directions = pass.directions;
  f.whiteness = pass.whiteness;
  f.series = pass.series;
}

/// A pooled fit's residual per log (PartResidual).
std::vector<PartResidual> part_residuals(const PreparedLog& log, const ResidualPass& pass) {
  std::vector<PartResidual> out;
  for (std::size_t part = 0; part < log.part_names.size() && part < pass.part_rss.size(); ++part) {
    const auto& rss = pass.part_rss[part];
    const auto& n = pass.part_n[part];
    auto of = [&](int g) { return n[static_cast<std::size_t>(g)] > 0 ? rms(rss[static_cast<std::size_t>(g)], n[static_cast<std::size_t>(g)]) : kNaN; };
    out.push_back({log.part_names[part], std::max({n[0], n[1] / 2, n[2] / 2}), of(0), of(1), of(2)});
  }
  return out;
}

/// Explained: every signal at its floor, in-sample and held back, and no outliers
/// that matter (the residual with them included also at the floor).
bool at_floor(const ModelFit& f, double explained_ratio) {
  bool ok = !f.signals.empty() && f.converged;
  for (const SignalResidual& r : f.signals) {
    if (r.rms > explained_ratio * r.floor) ok = false;
    if (std::isfinite(r.held_back_rms) && r.held_back_rms > explained_ratio * r.floor) ok = false;
    if (!f.outliers.empty() && r.rms_with_outliers > explained_ratio * r.floor) ok = false;
  }
  return ok;
}


/// In an explained model, the terms the log does not need: with a term's values at neutral
/// and every other column refitted (linearised at the fit: the cost rises by v' (M^-1_TT)^-1 v,
/// v the term's distance from neutral in the columns' coordinates, M the normal matrix, in
/// weighted units where a row at its floor weighs 1), every signal would stay within the
/// explained ratio even if the whole rise fell on it. Such a term may be formally
/// significant (its standard errors are small over many rows) and still take up less than
/// the noise: a mechanical pair beside a slow loop, 6.8 se from zero, moves the residual
/// from 1.126x to 1.130x its floor.
/// Terms with a nonlinear parameter are left out (the linearisation at their fit says
/// nothing of their neutral point, e.g. a tracking loop's ideal converter).
std::vector<std::string> unneeded_terms(const Design& d, const StepSolution& s, const ModelFit& f, double ratio) {
  std::vector<std::string> out;
  // The design's terms are the model's, in its order (design_for).
  if (!s.ok || d.terms().size() < 2 || d.terms().size() != f.model.spec().terms.size()) return out;
  const Eigen::VectorXd z = d.z();
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    const DesignTerm& t = d.terms()[i];
    const auto ps = t.effect->params();
    if (t.candidate || t.params.empty() ||
        std::any_of(t.params.begin(), t.params.end(), [&](int p) { return ps[static_cast<std::size_t>(p)].nonlinear; })) {
      continue;
    }
    Design neutral = d;
    for (const int p : t.params) neutral.terms()[i].values[static_cast<std::size_t>(p)] = ps[static_cast<std::size_t>(p)].neutral;
    const Eigen::VectorXd zn = neutral.z();
    const auto k = static_cast<Eigen::Index>(t.params.size());
    const int first = d.term_column(i);
    const Eigen::VectorXd v = z.segment(first, k) - zn.segment(first, k);
    const Eigen::MatrixXd block = s.inverse.block(first, first, k, k);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(block);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) continue;
    const double rise = v.dot(ldlt.solve(v));
    double before = 0.0, after = 0.0;
    bool fits = std::isfinite(rise);
    for (const SignalResidual& r : f.signals) {
      if (!(r.floor > 0.0) || r.rows <= 0) continue;
      const double x = r.rms / r.floor;
      const double y = std::sqrt(x * x + rise / static_cast<double>(r.rows));
      before = std::max(before, x);
      after = std::max(after, y);
      fits = fits && y <= ratio;
    }
    if (!fits) continue;
    out.push_back(fmt::format("{} is not needed to explain this log: at its neutral values, the other terms refitted "
                              "(linearised), the worst signal would go from {:.3f}x to {:.3f}x its floor (explained "
                              "up to {}x): whatever its standard errors say (they shrink with the log's length), it "
                              "takes up less than the noise, and a model without it is the plainer one",
                              f.model.spec().terms[i].reference(), before, after, ratio));
  }
  return out;
}

/// Why the model cannot be fitted to the log: which of its terms are aliases of one another
/// at the start values (fit_support.h aliased_terms), so the user knows which to leave out.
std::string not_separable_message(const ModelFit& f, const PreparedLog& log, const GroupFloors& floors) {
  std::string out = fmt::format("the model's effects ({}) are not separable with the signals in this log",
                                fmt::join(f.effects, ", "));
  const std::vector<std::size_t> aliased = aliased_terms(design_for(f.model, log), log.rows, floors);
  if (aliased.size() >= 2) {
    std::vector<std::string> names;
    names.reserve(aliased.size());
    for (const std::size_t i : aliased) names.push_back(f.model.spec().terms[i].reference());
    const std::string last = names.back();
    names.pop_back();
    out += fmt::format(": {} and {} are aliases here (at first order each is a combination of the others: they land on "
                       "the same harmonics of the angle{}); without any one of them the rest are separable, so leave "
                       "one out",
                       fmt::join(names, ", "), last, log.sincos ? " and of the sin/cos" : "");
  }
  if (!log.sincos) out += " (sin/cos would tell more effects apart: e.g. harmonics(k3) and amplitude_imbalance both land on 2 theta without them)";
  return out;
}

}  // namespace

std::vector<bool> apply_start_values(const FitStartValues& start, Model& model) {
  const std::vector<ModelParameter> own = model.parameters();
  for (const ModelParameter& p : start.values) {
    const bool known = std::any_of(own.begin(), own.end(), [&](const ModelParameter& o) { return o.name == p.name; });
    if (known && std::isfinite(p.value)) model.set(p.name, p.value);
  }
  const std::vector<std::string> refs = model.spec().references();
  std::vector<bool> settled(refs.size(), false);
  for (std::size_t i = 0; i < refs.size(); ++i) {
    settled[i] = std::find(start.settled.begin(), start.settled.end(), refs[i]) != start.settled.end();
  }
  return settled;
}

DiscoveryOptions offline_discovery_options() {
  DiscoveryOptions o;
  o.max_report_order = kOfflineReportOrder;
  o.harmonic_families = true;
  o.refit_proposed = true;
  return o;
}

ModelFit fit_prepared(const PreparedLog& log, std::span<const std::string> effects, const DiscoveryOptions& options) {
  const ModelSpec spec = ModelSpec::parse(effects, options.customs);
  check_model_against_log(spec, log);
  const GroupFloors floors = log.floors.floors();
  ModelFit f;
  f.model = Model(spec, log.p_r, log.p);
  f.effects = spec.references();
  const std::vector<bool> settled = apply_start_values(options.start, f.model);
  Design d = design_for(f.model, log);
  const FitResult fr = fit_design(
      d, log.rows, floors, 12,
      [&] {
        if (options.progress) options.progress(0.1);
      },
      settled);
  if (!fr.ok) {
    throw_if_custom_term_not_finite(f.effects, log, options);
    throw std::invalid_argument(not_separable_message(f, log, floors));
  }
  f.passes = fr.passes;
  f.model.take_values(d);
  const std::vector<int> cols = model_columns(d);
  // The nuisance-only fit of the same rows: the "raw" residual.
  Design raw(ModelSpec{}, {}, nuisances_for(log));
  raw.set_parts(log.part_count());
  PassStatistics raw_stats(raw.columns());
  accumulate(raw, log.rows, floors, raw_stats);
  ++f.passes;
  const StepSolution raw_sol = solve_step(raw_stats.all, floors);
  const std::vector<NuisanceValues> nv = nuisance_at_solution(d, fr, log, f);
  // One pass at the solution: breakdowns, whiteness, robust scores, series.
  const ResidualPass pass = residual_pass(d, log, floors, cols, options, nv);
  ++f.passes;
  const StepSolution& s = fr.last;
  fill_params(f, d, parameter_covariance(s, pass, cols, f));
  std::vector<std::string> convergence_notes = signal_residuals(log, fr, pass, raw_sol, floors, cols, f);
  if (!fr.converged && f.converged) {
    // The fit ended where its damped steps went uphill (or its passes ran out) with the
    // undamped step still worth more than a tenth of a standard error's cost
    // (least_squares.cpp step_negligible): the values are not a minimum the linearisation
    // can vouch for, so their standard errors say nothing of how far off they are.
    f.converged = false;
    convergence_notes.push_back(fmt::format(
        "the fit did not converge: it stopped after {} passes where its steps no longer lowered the cost, with "
        "its linearised step still moving the values by ~{:.2g} standard errors: some of the model's terms are "
        "nearly aliases here, or a parameter's valley is not smooth; the values may be off by that much",
        fr.passes, step_in_standard_errors(fr.last, fr.cost)));
  }
  if (const std::int64_t n = d.loop_balance_unconverged(log.rows); n > 0) {
    // The prediction at those rows is the balance's last iterate, not the loop's steady
    // state (loop_correction.h): whatever the residual, it is no evidence for the model.
    f.converged = false;
    convergence_notes.push_back(fmt::format(
        "r/d: the converter's loop has no steady state the model can compute at {} of the fitted rows: the "
        "envelopes' radius (the loop's gain) swings too far near the loop's resonance (|H| |r| >= 1); the "
        "R/D prediction there is not converged",
        n));
  }
  f.residual_rms_rad = f.signals.empty() ? 0.0 : f.signals.front().rms;
  f.noise_floor_rad = f.signals.empty() ? 0.0 : f.signals.front().floor;
  take_breakdowns(pass, f);
  f.parts = part_residuals(log, pass);
  f.floors = log.floors;
  f.account = account_of(log);
  f.outliers = log.outliers;
  f.bic = bic_of(s);
  f.rows = s.n[0] + s.n[1] + s.n[2];
  f.parameters = s.k;
  f.reference = log.reference;
  f.sincos_used = log.sincos;
  f.currents_used = log.currents;
  f.notes = log.notes;
  f.notes.insert(f.notes.end(), convergence_notes.begin(), convergence_notes.end());
  if (std::string n = unsupported_terms_note(d, f); !n.empty()) f.notes.push_back(std::move(n));
  // Faulty signals for a large part of the log (a dead excitation, a lost channel,
  // clipping, a lost track): a fit at the floor on them is no evidence.
  f.untrusted = !options.untrusted_input.empty();
  f.explained = at_floor(f, options.explained_ratio) && options.untrusted_input.empty();
  if (f.explained) {
    for (std::string& n : unneeded_terms(d, s, f, options.explained_ratio)) f.notes.push_back(std::move(n));
  }
  if (!f.robust_errors) {
    f.notes.push_back(fmt::format("standard errors are formal (only {} revolutions: the revolution-to-revolution "
                                  "spread needs {})",
                                  pass.blocks, kMinRobustBlocks));
  }
  return f;
}

ModelFit fit_model(const DiscoveryInput& input, std::span<const std::string> effects, const DiscoveryOptions& options) {
  const PreparedLog log = prepare_log(input, options.prepare);
  return fit_prepared(log, effects, options);
}

namespace {

/// What a missing pair's summary adds where the log cannot tell a member of the pair from
/// other candidates (Candidate::fits_as_well): each such pair fits as well, so naming one
/// alone would be a confident answer the data does not support ("" where none).
std::string pair_alternatives(const std::vector<std::string>& pair, const std::vector<Candidate>& candidates,
                              bool sincos) {
  std::vector<std::string> alike;
  for (const std::string& member : pair) {
    const auto c = std::find_if(candidates.begin(), candidates.end(),
                                [&member](const Candidate& x) { return x.effect == member; });
    if (c == candidates.end() || c->fits_as_well.empty()) continue;
    alike.push_back(fmt::format("{} from {}", member, fmt::join(c->fits_as_well, " or ")));
  }
  if (alike.empty()) return {};
  return fmt::format(" This log cannot tell {} (they fit as well here{}).", fmt::join(alike, ", nor "),
                     sincos ? "" : "; sin/cos envelopes would tell them apart");
}

Explanation explain_steps(const PreparedLog& log, std::span<const std::string> effects,
                          const DiscoveryOptions& options) {
  Explanation ex;
  ex.fit = fit_prepared(log, effects, options);
  if (options.progress) options.progress(0.4);
  if (ex.fit.untrusted) {
    // Neither "explained" nor a proposed effect: candidates fitted to faulty signals
    // would name the fault's shape, not the resolver's physics.
    ex.verdict = Verdict::kUnexplained;
    for (const std::string& u : options.untrusted_input) ex.where_it_fails.push_back("signal health: " + u);
    bool at_floor = true;
    for (const SignalResidual& r : ex.fit.signals) at_floor = at_floor && r.rms <= options.explained_ratio * r.floor;
    if (!at_floor) {
      for (std::string& w : describe_failure(log, ex.fit, options.explained_ratio)) ex.where_it_fails.push_back(std::move(w));
    }
    ex.summary = fmt::format("unexplained: the signals are faulty for a large part of the log ({}){}: a fit on them "
                             "says nothing about the resolver, and no effect is proposed; fix the input (see the "
                             "faults' start times) and record again.",
                             fmt::join(options.untrusted_input, "; "),
                             at_floor ? fmt::format(", although every residual is within {}x its noise floor",
                                                    num(options.explained_ratio))
                                      : std::string());
    return ex;
  }
  if (ex.fit.explained && !options.rank_when_explained) {
    ex.verdict = Verdict::kExplained;
    ex.summary = "explained: every signal's residual is within " + num(options.explained_ratio) +
                 "x its noise floor, on held-back samples too; no effect is needed (candidates not ranked).";
    return ex;
  }
  Ranking ranking = rank_candidates(log, ex.fit, options);
  const std::vector<ScreenedPair> screened_pairs = std::move(ranking.screened_pairs);
  ex.candidates = std::move(ranking.candidates);
  ex.not_evaluated = std::move(ranking.not_evaluated);
  ex.fit.passes += ranking.passes;
  if (options.progress) options.progress(0.8);
  bool outliers_matter = false;
  for (const SignalResidual& r : ex.fit.signals) {
    outliers_matter = outliers_matter || (!ex.fit.outliers.empty() && r.rms_with_outliers > options.explained_ratio * r.floor);
  }
  if (ex.fit.explained) {
    for (Candidate& c : ex.candidates) c.proposed = false;
    ex.verdict = Verdict::kExplained;
    ex.summary = "explained: every signal's residual is within " + num(options.explained_ratio) +
                 "x its noise floor, on held-back samples too; no effect is needed.";
    return ex;
  }
  ex.where_it_fails = describe_failure(log, ex.fit, options.explained_ratio);
  // The model without the outliers may already explain the log.
  bool in_sample_ok = true;
  for (const SignalResidual& r : ex.fit.signals) {
    if (r.rms > options.explained_ratio * r.floor) in_sample_ok = false;
  }
  if (outliers_matter && in_sample_ok) {
    const std::int64_t count = ex.fit.account.outliers;  // rows: one with spikes on two signals is one sample
    ex.verdict = Verdict::kUnexplained;
    double worst = 0.0;
    for (const SignalResidual& r : ex.fit.signals) worst = std::max(worst, r.rms_with_outliers / r.floor);
    ex.summary = fmt::format("unexplained: {} impulsive samples (outliers) carry the residual to {}x the floor; "
                             "without them the model explains the log. Find their source (EMI, bit errors) before "
                             "trusting a fit; they are kept out of this one.",
                             count, num(worst, "%.1f"));
    return ex;
  }
  const Candidate* best = ex.candidates.empty() || !ex.candidates.front().proposed ? nullptr : &ex.candidates.front();
  bool named = false;
  if (best != nullptr) {
    named = best->reaches_floor || removes_most_excess(ex.fit.signals, ex.fit.rows, log.rd, best->weighted_rss);
  }
  // A best candidate that removes most of the excess but does not reach the floor may be
  // the wrong one: two effects at real magnitudes (a 2.5 % quadrature and a phased K_3 under
  // a 12 % imbalance at p_r = 3) leave 2 theta where one mechanical order fits most of it
  // (12.6x the floor, the envelopes 21x) while the two reach it. A pair that does wins.
  if (best != nullptr && !best->reaches_floor) {
    ex.missing_pair = find_missing_pair(log, ex.fit, ex.candidates, options, screened_pairs,
                                        named ? PairSearch::kScreened : PairSearch::kEvery);
  }
  const std::string alternatives =
      best == nullptr || best->fits_as_well.empty()
          ? std::string()
          : fmt::format(" This log cannot tell it from {} (they fit as well here{}).", fmt::join(best->fits_as_well, ", "),
                        log.sincos ? "" : "; sin/cos envelopes would tell them apart");
  if (!ex.missing_pair.empty()) {
    ex.verdict = Verdict::kMissingEffect;
    // The pair's first, not the ranking's: a family or an alike candidate may rank above it.
    const Candidate& first = *std::find_if(ex.candidates.begin(), ex.candidates.end(),
                                           [&ex](const Candidate& c) { return c.effect == ex.missing_pair[0]; });
    ex.summary = "missing_effect: two effects are missing: " + ex.missing_pair[0] + " and " + ex.missing_pair[1] +
                 " together bring every signal to within " + num(options.explained_ratio) +
                 "x its noise floor (neither does alone); " + first.change(true) + " first. " + first.reason +
                 pair_alternatives(ex.missing_pair, ex.candidates, log.sincos);
  } else if (named) {
    ex.verdict = Verdict::kMissingEffect;
    struct Change {
      const char* what;
      double before, after, floor;
      const char* unit;
    };
    std::vector<Change> changes;
    for (const SignalResidual& r : ex.fit.signals) {
      if (r.signal == "position_error") changes.push_back({"position-error", r.rms, best->residual_after_rad, r.floor, " rad"});
      if (r.signal == "sin_cos") changes.push_back({"sin/cos", r.rms, best->sincos_residual_after, r.floor, " of the amplitude"});
      if (r.signal == "i_dq") changes.push_back({"i_dq", r.rms, best->dq_residual_after, r.floor, " A"});
    }
    const Change& c = *std::max_element(changes.begin(), changes.end(), [](const Change& x, const Change& y) {
      return (x.before - x.after) / x.floor < (y.before - y.after) / y.floor;
    });
    ex.summary = "missing_effect: " + best->change() + " brings the " + c.what + " residual from " +
                 num(c.before) + " to " + num(c.after) + c.unit + " (floor " + num(c.floor) + "); " + best->reason +
                 alternatives;
  } else {
    ex.verdict = Verdict::kUnexplained;
    ex.summary = "unexplained: no catalog effect brings the residual near the noise floor; the residual is "
                 "described above instead of naming an effect.";
    if (!ex.fit.signals.empty() && ex.fit.signals.front().rms > options.explained_ratio * ex.fit.noise_floor_rad) {
      ex.suggested_custom = suggest_custom(log, ex.fit, options);
      if (!ex.suggested_custom.empty()) {
        std::string names;
        for (std::size_t at = ex.suggested_custom.find("name = \""); at != std::string::npos;
             at = ex.suggested_custom.find("name = \"", at + 1)) {
          const std::size_t b = at + 8, e = ex.suggested_custom.find('"', b);
          names += (names.empty() ? "" : ", ") + ex.suggested_custom.substr(b, e - b);
        }
        ex.summary += " [[model.custom]] blocks that describe it are suggested: paste them into the config and add " +
                      names + " to [model] effects.";
      }
    }
  }
  return ex;
}

}  // namespace

Explanation explain_prepared(const PreparedLog& log, std::span<const std::string> effects,
                             const DiscoveryOptions& options) {
  Explanation ex = explain_steps(log, effects, options);
  if (options.progress) options.progress(1.0);
  return ex;
}

Explanation explain_model(const DiscoveryInput& input, std::span<const std::string> effects,
                          const DiscoveryOptions& options) {
  const PreparedLog log = prepare_log(input, options.prepare);
  if (options.progress) options.progress(0.05);
  return explain_prepared(log, effects, options);
}

}  // namespace resolver
