#include "daemon/core/discovery/ranking.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <functional>
#include <map>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "daemon/core/discovery/coverage.h"
#include "daemon/core/discovery/fit_support.h"
#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/model/custom_effect.h"
#include "daemon/core/model/least_squares.h"
#include "daemon/core/model/model.h"

namespace resolver {

namespace {

/// Orders of the residual the harmonic families are tried at: the largest ones
/// above 4 standard errors of a harmonic amplitude (floor sqrt(2 / n)), at most this many.
constexpr int kOrdersTried = 3;
constexpr double kSignificance = 4.0;
/// Nonlinear candidates refitted to convergence (the best by their linearised score).
constexpr int kNonlinearRefits = 3;
/// Candidates checked for being aliases of model terms (offer_swaps), on every
/// kAliasRowStride-th row (an eighth of a pass each), and of those found the first
/// kSwapFits fitted in place of the terms they alias (a fit each).
constexpr int kAliasChecks = 16;
constexpr std::size_t kAliasRowStride = 8;
constexpr int kSwapFits = 2;
/// Candidates within this BIC of each other, or whose residuals differ by less than
/// this share of the smaller, are not told apart by the log (e.g. K_3 and a 6th mechanical
/// harmonic with p_r = 3: the same 2 theta in the angle, and alpha takes up the
/// radius; channel delay and quadrature at one speed).
constexpr double kIndistinguishableBic = 10.0;
constexpr double kIndistinguishableShare = 0.02;

/// A family candidate (every significant order at once) is tried from this many orders:
/// a saturation pattern spreads over many, and one order at a time would take as many steps.
constexpr int kFamilyFrom = 4;

std::vector<int> significant_orders(const std::vector<HarmonicResidual>& h, double floor, std::int64_t n, int lowest,
                                    int most = kOrdersTried) {
  std::vector<HarmonicResidual> v;
  const double se = floor * std::sqrt(2.0 / std::max<double>(1.0, static_cast<double>(n)));
  for (const HarmonicResidual& x : h) {
    if (x.order >= lowest && x.amplitude > kSignificance * se) v.push_back(x);
  }
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.amplitude > b.amplitude; });
  std::vector<int> out;
  for (std::size_t i = 0; i < v.size() && static_cast<int>(i) < most; ++i) out.push_back(v[i].order);
  return out;
}

bool in_model(const ModelSpec& spec, const Effect& e, int param) {
  const ModelTerm* t = spec.find(e);
  return t != nullptr && std::find(t->params.begin(), t->params.end(), param) != t->params.end();
}

/// A family (CandidateParams::family) of one effect: every group's parameters not
/// yet in the model, ascending, or empty when fewer than kFamilyFrom groups are left.
ModelTerm family_term(const Effect& e, const ModelSpec& spec, const std::vector<std::vector<std::string>>& groups) {
  std::vector<int> params;
  int count = 0;
  for (const std::vector<std::string>& names : groups) {
    bool any = false;
    for (const std::string& name : names) {
      const int i = find_param(e, name);
      if (i < 0 || in_model(spec, e, i)) continue;
      params.push_back(i);
      any = true;
    }
    count += any ? 1 : 0;
  }
  if (count < kFamilyFrom) return ModelTerm{&e, {}};
  std::sort(params.begin(), params.end());
  return ModelTerm{&e, params};
}

/// A listed candidate: its parameters, or empty when one is unknown or already in the model.
ModelTerm listed_term(const Effect& e, const ModelSpec& spec, const std::vector<std::string>& names) {
  std::vector<int> params;
  for (const std::string& name : names) {
    const int i = find_param(e, name);
    if (i < 0 || in_model(spec, e, i)) return ModelTerm{&e, {}};
    params.push_back(i);
  }
  return ModelTerm{&e, params};
}

/// The fit's residual spectra as the effects ask for them (Effect::residual_candidates).
class FitResidualSpectrum final : public ResidualSpectrum {
 public:
  FitResidualSpectrum(const ModelFit& fit, std::int64_t n) : fit_(fit), n_(n) {}
  [[nodiscard]] std::vector<int> significant(Angle angle, int lowest, int most) const override {
    return significant_orders(angle == Angle::kResolver ? fit_.harmonics : fit_.harmonics_mech, fit_.noise_floor_rad,
                              n_, lowest, most);
  }
  [[nodiscard]] std::vector<int> strongest(Angle angle, int lowest) const override {
    return significant(angle, lowest, kOrdersTried);
  }

 private:
  const ModelFit& fit_;
  std::int64_t n_;
};

/// The candidate terms: defaults of every fittable effect not in the model, the
/// harmonic families at the residual's orders, the config's custom effects.
std::vector<ModelTerm> candidate_terms(const PreparedLog& log, const ModelFit& fit, const DiscoveryOptions& opt,
                                       std::vector<std::string>& not_evaluated) {
  std::vector<ModelTerm> out;
  const ModelSpec& spec = fit.model.spec();
  auto usable = [&](const ModelTerm& t) {
    const std::string name = t.reference();
    if (t.effect->needs_reference() && !log.reference) {
      not_evaluated.push_back(name + ": needs the reference angle");
      return false;
    }
    if (t.effect->needs_aligned_reference() && !log.reference_aligned) {
      not_evaluated.push_back(name + ": " + std::string(kNeedsAlignedReference));
      return false;
    }
    if (t.effect->current_side() && !log.currents) {
      not_evaluated.push_back(name + ": needs the phase currents (and the reference angle)");
      return false;
    }
    if (const std::string missing = motion_missing(*t.effect, log.motion, log.sincos && log.rd); !missing.empty()) {
      not_evaluated.push_back(name + ": not identifiable here: " + missing);
      return false;
    }
    const CoverageCheck c = check_coverage(log.rows, needed_orders(t));
    if (!c.ok) {
      not_evaluated.push_back(name + ": " + c.missing);
      return false;
    }
    return true;
  };
  std::vector<const Effect*> answered;
  for (const ModelTerm& t : residual_candidate_terms(fit, opt, &answered)) {
    if (usable(t)) out.push_back(t);
  }
  for (const Effect* e : effect_registry()) {
    if (!e->fittable() || std::find(answered.begin(), answered.end(), e) != answered.end()) continue;
    if (spec.find(*e) != nullptr) {
      // The parameters the catalog does not fit by default that the model's term holds
      // (a loop's zeta at 0.7): a lightly damped or slow loop's resonance is what they
      // add. Without this the user's loop on such a converter went on to mechanical
      // harmonics from tracking_loop(omega_n) and never recovered (docs/ACCURACY.md).
      std::vector<int> held;
      for (int i = 0; i < static_cast<int>(e->params().size()); ++i) {
        const ParamInfo& p = e->params()[static_cast<std::size_t>(i)];
        if (!p.default_fit && !in_model(spec, *e, i)) held.push_back(i);
      }
      const ModelTerm t{e, held};
      if (!held.empty() && usable(t)) out.push_back(t);
      continue;
    }
    const ModelTerm t{e, default_params(*e)};
    if (!t.params.empty() && usable(t)) out.push_back(t);
  }
  if (opt.customs != nullptr) {
    for (const auto& c : opt.customs->all()) {
      if (spec.find(*c) != nullptr) continue;
      std::vector<int> all;
      for (int i = 0; i < static_cast<int>(c->params().size()); ++i) all.push_back(i);
      const ModelTerm t{c.get(), all};
      if (usable(t)) out.push_back(t);
    }
  }
  return out;
}

}  // namespace

/// What the log's motion (or signals) lacks for `e` to be identifiable, as advice
/// ("" = nothing). One speed: the moving speeds span less than 10 % of the fastest (a
/// bench's speed ripple is a few percent; a step or ramp is far more). `sincos`: the
/// fit has the envelopes' rows beside the R/D angle's.
std::string motion_missing(const Effect& e, const MotionSummary& m, bool sincos) {
  const bool reversal = m.reversals > 0;
  const double fastest = std::max(std::abs(m.omega_min), std::abs(m.omega_max));
  const bool speed_change = m.omega_max - m.omega_min > 0.1 * fastest;
  switch (e.identifiable_with()) {
    case Effect::Needs::kNothing: return "";
    case Effect::Needs::kSpeedChangeOrReversal:
      return speed_change || reversal ? ""
                                      : "at one speed in one direction it is a constant turn of the angle; record "
                                        "a speed step, a ramp or an out-and-back";
    case Effect::Needs::kSpeedChangeOrSinCos:
      // A 3 % gain error at 600 r/min with a 3000 rad/s loop leaves 6e-5 rad at 2 theta
      // in the R/D angle alone (2x its floor): with sin/cos the fit finds omega_n to 0.1 %.
      return speed_change || sincos ? ""
                                    : "at one speed, with the R/D angle alone, it only turns and scales each error "
                                      "harmonic by a constant; record a ramp or speed steps, or log the sin/cos "
                                      "envelopes (the loop filters only the R/D angle)";
    case Effect::Needs::kReversal:
      return reversal ? "" : "in one direction a play is a constant; record an out-and-back (a reversal)";
  }
  return "";
}

std::string reason_of(const ModelTerm& t, const std::vector<ModelParameter>& params, bool one_step) {
  std::string vals;
  const std::string prefix = std::string(t.effect->name()) + ".";
  for (const ModelParameter& p : params) {
    const bool own = p.name.starts_with(prefix);  // another term's parameter keeps its whole name
    vals += (vals.empty() ? "" : ", ") + (own ? p.name.substr(prefix.size()) : p.name) + " = " + num(p.value) + " +- " +
            num(p.std_error, "%.2g");
  }
  return std::string(t.effect->physics()) + (one_step ? " (one linearised step: " : " (fit: ") + vals + ").";
}

namespace {

/// Standard error of parameter `p` of `t` (column `col`, internal coordinate `z` for the
/// inverse-square scale) in value coordinates from a solution's inverse: a polar pair's
/// amplitude and phase through the polar map (fit_support.h).
double value_std_error(const DesignTerm& t, std::size_t p, const StepSolution& s, int col, double z) {
  const ParamInfo& info = t.effect->params()[p];
  const double s2 = s.rss_w / std::max(1.0, static_cast<double>(s.n[0] + s.n[1] + s.n[2] - s.k));
  if (info.polar == Polar::kAmplitude || info.polar == Polar::kPhase) {
    const int cx = info.polar == Polar::kAmplitude ? col : col - 1;
    return polar_std_error(t, p, s2 * Eigen::Matrix2d(s.inverse.block(cx, cx, 2, 2)));
  }
  double se = std::sqrt(std::max(0.0, s2 * s.inverse(col, col)));
  if (info.nonlinear && info.scale == FitScale::kInverseSquare) se *= 0.5 * std::pow(std::max(z, 1e-300), -1.5);
  return se;
}

}  // namespace

std::vector<ModelParameter> term_params(const Design& design, std::size_t term, const StepSolution& s, bool step) {
  Design moved = design;
  DesignTerm& dt = moved.terms()[term];
  dt.candidate = false;  // let step() move it
  const Eigen::VectorXd z_at = moved.z();  // where the step starts (a candidate: neutral)
  if (step) moved.step(s.dz);
  std::vector<ModelParameter> out;
  for (std::size_t k = 0; k < dt.params.size(); ++k) {
    const auto p = static_cast<std::size_t>(dt.params[k]);
    const ParamInfo& info = dt.effect->params()[p];
    const int col = design.term_column(term) + static_cast<int>(k);
    const double z = z_at[col] + (step ? s.dz[col] : 0.0);
    out.push_back({std::string(dt.effect->name()) + "." + std::string(info.name), dt.values[p],
                   value_std_error(dt, p, s, col, z), std::string(info.unit)});
  }
  return out;
}

void score_candidate(Candidate& c, const StepSolution& s, bool rd, const StepSolution& base, const GroupFloors& floors,
                     const DiscoveryOptions& options) {
  const double base_bic = bic_of(base);
  c.residual_after_rad = rms(rd ? s.rss[0] : s.rss[1], rd ? s.n[0] : s.n[1]);
  c.sincos_residual_after = rms(s.rss[1], s.n[1]);
  c.dq_residual_after = rms(s.rss[2], s.n[2]);
  c.weighted_rss = s.rss_w;
  c.score = bic_of(s);
  c.bic_drop = base_bic - c.score;
  c.err = base.rss_w > 0.0 ? (base.rss_w - s.rss_w) / base.rss_w : 0.0;
  c.proposed = c.bic_drop > options.proposal_bic_drop;
  c.reaches_floor = groups_explained(s, floors, options.explained_ratio);
}

bool needs_exact_refit(const Candidate& c, const DiscoveryOptions& options) {
  const ModelSpec one = ModelSpec::parse(std::vector<std::string>{c.effect}, options.customs);
  const ModelTerm& term = one.terms.front();
  if (options.refit_proposed && c.proposed && !c.family) return true;
  bool nonlinear = term.effect->envelope_only() && !c.family && !c.reaches_floor;
  for (int p : term.params) nonlinear = nonlinear || term.effect->params()[static_cast<std::size_t>(p)].nonlinear;
  return nonlinear;
}

void flag_one_step(Candidate& c, const DiscoveryOptions& options) {
  c.stepped = !c.refitted && needs_exact_refit(c, options);
  if (!c.stepped) return;
  const ModelSpec one = ModelSpec::parse(std::vector<std::string>{c.effect}, options.customs);
  c.reason = reason_of(one.terms.front(), c.params, true);
}

StepSolution solve_candidate(const std::vector<NormalEquations>& groups, const GroupFloors& floors,
                             const std::vector<int>& base_cols, std::span<const int> term_cols, ModelTerm& t) {
  std::vector<int> cols = base_cols;
  cols.insert(cols.end(), term_cols.begin(), term_cols.end());
  StepSolution s = solve_step(groups, floors, cols);
  if (s.ok || t.params.size() <= 1) return s;
  StepSolution best_part;
  std::size_t best_k = 0;
  for (std::size_t k = 0; k < term_cols.size(); ++k) {
    if (t.effect->params()[static_cast<std::size_t>(t.params[k])].polar != Polar::kNone) continue;
    std::vector<int> one = base_cols;
    one.push_back(term_cols[k]);
    const StepSolution part = solve_step(groups, floors, one);
    if (part.ok && (!best_part.ok || part.rss_w < best_part.rss_w)) {
      best_part = part;
      best_k = k;
    }
  }
  if (!best_part.ok) return s;
  t = ModelTerm{t.effect, {t.params[best_k]}};
  return best_part;
}

std::vector<std::string> exact_refits(const std::vector<Candidate>& ranked, const DiscoveryOptions& options) {
  std::vector<std::string> out;
  for (const Candidate& c : ranked) {
    if (static_cast<int>(out.size()) < kNonlinearRefits && c.proposed && needs_exact_refit(c, options)) {
      out.push_back(c.effect);
    }
  }
  return out;
}

namespace {


/// The index in `spec` of the term `term` is (or joins: a harmonic order beside the
/// model's orders, ModelSpec::add).
std::size_t term_index(const ModelSpec& spec, const ModelTerm& term) {
  std::size_t at = spec.terms.size() - 1;
  while (at > 0 && spec.terms[at].effect != term.effect) --at;
  return at;
}

/// The candidate's own parameters among a fitted term's (a joined term has the model's too).
std::vector<ModelParameter> own_params(const ModelTerm& term, std::vector<ModelParameter> fitted) {
  std::erase_if(fitted, [&](const ModelParameter& q) {
    for (std::size_t k = 0; k < term.params.size(); ++k) {
      if (q.name == term.param_name(k)) return false;
    }
    return true;
  });
  return fitted;
}

/// Nonlinear candidates: the linearised step is only the start; the best proposed
/// ones are refitted to convergence with the model. Envelope effects enter through
/// atan2 too: at real magnitudes (a 15 % harmonic) one linearised step from zero
/// leaves second-order terms far above the floor. Where that step already reaches
/// the floor (small magnitudes) a refit would only cost the live daemon its time.
void refit_nonlinear(Ranking& out, const PreparedLog& log, const ModelFit& fit, const StepSolution& base,
                     const GroupFloors& floors, const DiscoveryOptions& options) {
  for (const std::string& effect : exact_refits(out.candidates, options)) {
    Candidate& c = *std::find_if(out.candidates.begin(), out.candidates.end(),
                                 [&](const Candidate& x) { return x.effect == effect; });
    const ModelSpec one = ModelSpec::parse(std::vector<std::string>{c.effect}, options.customs);
    const ModelTerm& term = one.terms.front();
    ModelSpec with = fit.model.spec();
    with.add(term);
    // A candidate of an effect the model has (a harmonic order beside the model's orders)
    // joins that term (ModelSpec::add); any other is a term of its own, the last.
    const bool own_term = with.terms.size() > fit.model.spec().terms.size();
    const std::size_t at = term_index(with, term);
    // The model's terms start at its converged fit (their valleys chosen there, with
    // their other starts); the candidate's own parameters are started again, unless
    // the options settle it (a live window's refit starts where the last window's
    // converged: live_model_fit.h).
    Model candidate_start(one, log.p_r, log.p);
    const bool warm = apply_start_values(options.start, candidate_start).front();
    std::vector<std::vector<double>> values = fit.model.values();
    if (own_term) {
      values.push_back(warm ? candidate_start.values().front() : std::vector<double>{});
    } else if (warm) {
      const std::vector<double>& start = candidate_start.values().front();
      for (int p : term.params) {
        const auto i = static_cast<std::size_t>(p);
        if (i < values[at].size() && i < start.size()) values[at][i] = start[i];
      }
    }
    Design dm(with, values, nuisances_for(log));
    dm.set_parts(log.part_count());
    std::vector<bool> settled(dm.terms().size(), true);
    if (own_term) settled[at] = warm;
    const FitResult fr = fit_design(dm, log.rows, floors, 12, {}, settled);
    out.passes += fr.passes;
    // A refit that stopped where its steps went uphill (a candidate nearly an alias of model
    // terms) is no fit: the candidate keeps its linearised step, said so (flag_one_step).
    if (!fr.ok || !fr.converged) continue;
    c.refitted = true;
    score_candidate(c, fr.last, log.rd, base, floors, options);
    c.params = own_params(term, term_params(dm, at, fr.last, false));
    c.reason = reason_of(term, c.params);
  }
}

/// The model without `part` of its term `replaced` (the whole term, or the parameters of it
/// that a candidate aliases: harmonics(k2,k2_q) of harmonics(k2,k3,k2_q,k3_q)), the taken
/// parameters at their neutral values.
void take_out(ModelSpec& spec, std::vector<std::vector<double>>& values, std::size_t replaced, const ModelTerm& part) {
  ModelTerm& t = spec.terms[replaced];
  if (part.params.size() >= t.params.size()) {
    spec.terms.erase(spec.terms.begin() + static_cast<std::ptrdiff_t>(replaced));
    values.erase(values.begin() + static_cast<std::ptrdiff_t>(replaced));
    return;
  }
  for (const int p : part.params) {
    std::erase(t.params, p);
    const auto i = static_cast<std::size_t>(p);
    if (i < values[replaced].size()) values[replaced][i] = t.effect->params()[i].neutral;
  }
}

/// The model with candidate `term` in place of `part` of its term `replaced` (take_out),
/// fitted exactly (the model's other terms settled at their fit, the candidate started
/// again; one that joins a model term starts from zero beside that term's fitted orders);
/// nullopt where that fit does not converge.
std::optional<Candidate> swapped_fit(const ModelTerm& term, std::size_t replaced, const ModelTerm& part, const PreparedLog& log, const ModelFit& fit, const StepSolution& base,
                                     const GroupFloors& floors, const DiscoveryOptions& options, int& passes) {
  ModelSpec swapped = fit.model.spec();
  std::vector<std::vector<double>> values = fit.model.values();
  const std::string replaced_reference = part.reference();
  take_out(swapped, values, replaced, part);
  const std::size_t before = swapped.terms.size();
  swapped.add(term);
  const bool own_term = swapped.terms.size() > before;
  if (own_term) values.emplace_back();
  const std::size_t at = term_index(swapped, term);
  Design dm(swapped, values, nuisances_for(log));
  dm.set_parts(log.part_count());
  std::vector<bool> settled(dm.terms().size(), true);
  if (own_term) settled[at] = false;
  const FitResult fr = fit_design(dm, log.rows, floors, 12, {}, settled);
  passes += fr.passes;
  if (!fr.ok || !fr.converged) return std::nullopt;
  Candidate out;
  out.effect = term.reference();
  out.replaces = replaced_reference;
  out.refitted = true;
  score_candidate(out, fr.last, log.rd, base, floors, options);
  out.params = own_params(term, term_params(dm, at, fr.last, false));
  out.reason = reason_of(term, out.params) + " In place of " + replaced_reference +
               ": with both in the model the fit cannot separate them (aliases at first order).";
  return out;
}

/// A candidate the model cannot take beside some of its terms.
struct Alias {
  std::optional<std::size_t> candidate;  ///< index in the ranking's candidates (none: not separable there)
  ModelTerm term;                     ///< the candidate's
  std::vector<ModelTerm> replaced;  ///< what of the model it aliases: a term, or the part of it the candidate names
  std::vector<std::size_t> at;     ///< the model's terms they are of
};

/// The model terms candidate `c` aliases (fit_support.h aliased_terms on `rows`, the model
/// with `c` at the start values, where the user's next fit starts); empty when none.
std::optional<Alias> alias_of(const ModelTerm& term, std::optional<std::size_t> index, const PreparedLog& log,
                              const ModelFit& fit, std::span<const FitRow> rows, const GroupFloors& floors) {
  ModelSpec with = fit.model.spec();
  with.add(term);
  if (with.parameter_count() == fit.model.spec().parameter_count()) return std::nullopt;  // the model has them already
  const std::size_t own = term_index(with, term);
  const std::vector<std::size_t> aliased = aliased_terms(design_for(Model(with, log.p_r, log.p), log), rows, floors);
  // Only with another term: a column that is zero at the start (a nonlinear parameter at
  // its neutral value) makes the candidate alone "aliased", and the fit steps past it.
  if (std::find(aliased.begin(), aliased.end(), own) == aliased.end() || aliased.size() < 2) return std::nullopt;
  Alias out{index, term, {}, {}};
  const std::vector<std::string> declared = term.effect->first_order_aliases(term.params, log.p_r);
  for (const std::size_t m : aliased) {
    if (m == own) continue;  // a term the candidate joins is kept, with it
    ModelTerm part = with.terms[m];
    // Of a term with more orders than the candidate aliases, only those it names
    // (eccentricity at p_r = 1 takes k2 of harmonics(k2,k3,k2_q,k3_q), not k3).
    for (const std::string& reference : declared) {
      const ModelTerm d = ModelSpec::parse(std::vector<std::string>{reference}).terms.front();
      const bool within = d.effect == part.effect && std::all_of(d.params.begin(), d.params.end(), [&](int p) {
        return std::find(part.params.begin(), part.params.end(), p) != part.params.end();
      });
      if (within) part = d;
    }
    out.replaced.push_back(std::move(part));
    out.at.push_back(m);
  }
  return out;
}

/// Offline: a candidate that the model cannot take beside its terms (the model with it is
/// not separable from the start values) is an alias of some of them at first order; the
/// log tells them apart only at second order, where the wrong one of two aliases leaves a
/// residual that draws further, spurious candidates. It is never proposed as an addition
/// (the fit would refuse it), and the first kSwapFits such candidates as listed are fitted
/// exactly in place of each term they alias, and offered so. A mechanical harmonic at a
/// whole electrical order (the winding terms' alias) is the case met (docs/ACCURACY.md).
void offer_swaps(Ranking& out, std::span<const ModelTerm> unseparated, const PreparedLog& log, const ModelFit& fit,
                 const StepSolution& base, const GroupFloors& floors, const DiscoveryOptions& options) {
  if (!options.refit_proposed) return;
  // An alias is singular at the start values whatever the rows: a sample of them tells.
  std::vector<FitRow> sample;
  for (std::size_t i = 0; i < log.rows.size(); i += kAliasRowStride) sample.push_back(log.rows[i]);
  std::vector<Alias> found;
  int checked = 0;
  const auto check = [&](const ModelTerm& t, std::optional<std::size_t> index) {
    ++checked;
    if (std::optional<Alias> a = alias_of(t, index, log, fit, sample, floors)) found.push_back(std::move(*a));
  };
  for (std::size_t i = 0; i < out.candidates.size() && checked < kAliasChecks; ++i) {
    const Candidate& c = out.candidates[i];
    if (c.family || !c.replaces.empty()) continue;
    check(ModelSpec::parse(std::vector<std::string>{c.effect}, options.customs).terms.front(), i);
  }
  // Those the ranking could not separate from the model at its fit: the aliases whose
  // second-order difference is too small there to be a column of their own.
  for (const ModelTerm& t : unseparated) {
    if (!is_family(t)) check(t, std::nullopt);
  }
  // Each model term's own aliases at the log's p_r (Effect::first_order_aliases): once the
  // model's term took their orders the residual no longer asks for them, so they are not
  // listed (at p_r = 1 a mechanical pair of order 2 stands for harmonics(k3,k3_q) and the
  // quadrature).
  for (const ModelTerm& m : fit.model.spec().terms) {
    for (const std::string& reference : m.effect->first_order_aliases(m.params, log.p_r)) {
      const ModelTerm t = ModelSpec::parse(std::vector<std::string>{reference}, options.customs).terms.front();
      if (t.effect->needs_reference() && !log.reference) continue;
      if (already_listed(out.candidates, reference)) continue;  // checked above, as listed
      check(t, std::nullopt);
    }
  }
  const int stride = static_cast<int>(kAliasRowStride);
  out.passes += (checked + stride - 1) / stride;
  std::vector<Candidate> swaps;
  int fitted = 0;
  for (const Alias& a : found) {
    const std::size_t before = swaps.size();
    if (fitted < kSwapFits) {
      ++fitted;
      for (std::size_t k = 0; k < a.at.size(); ++k) {
        if (std::optional<Candidate> s = swapped_fit(a.term, a.at[k], a.replaced[k], log, fit, base, floors, options, out.passes)) {
          swaps.push_back(std::move(*s));
        }
      }
    }
    if (!a.candidate) continue;
    Candidate& c = out.candidates[*a.candidate];
    std::vector<std::string> names;
    names.reserve(a.replaced.size());
    for (const ModelTerm& t : a.replaced) names.push_back(t.reference());
    c.reason += fmt::format(" Not an addition: with the model it is not separable from {} (aliases at first order){}.",
                            fmt::join(names, ", "), swaps.size() > before ? "; listed in place of it" : "");
    c.proposed = false;
  }
  for (Candidate& s : swaps) out.candidates.push_back(std::move(s));
}

/// Alike: what they leave differs by less than the BIC's resolution, or by less
/// than a small share of what the better one leaves (second-order differences of a
/// large effect); never when only one of them reaches the floor.
bool alike(const Candidate& a, const Candidate& b) {
  if (a.reaches_floor != b.reaches_floor) return false;
  const double left = std::min(a.weighted_rss, b.weighted_rss);
  return std::abs(a.score - b.score) < kIndistinguishableBic ||
         std::abs(a.weighted_rss - b.weighted_rss) < kIndistinguishableShare * left;
}

/// Among candidates the log cannot tell apart (each lists the others), the simplest
/// first: fewer parameters, then one that needs no change of speed (constant at one
/// speed is the plainer explanation), then the lower BIC.
void order_alike_simplest_first(std::vector<Candidate>& candidates, const DiscoveryOptions& options) {
  for (Candidate& c : candidates) {
    if (!c.proposed) continue;
    for (const Candidate& o : candidates) {
      if (&o != &c && o.proposed && alike(c, o)) c.fits_as_well.push_back(o.effect);
    }
  }
  auto simpler = [&options](const Candidate& a, const Candidate& b) {
    const ModelSpec sa = ModelSpec::parse(std::vector<std::string>{a.effect}, options.customs);
    if (a.params.size() != b.params.size()) return a.params.size() < b.params.size();
    const ModelSpec sb = ModelSpec::parse(std::vector<std::string>{b.effect}, options.customs);
    const bool va = sa.terms.front().effect->needs_speed_change(), vb = sb.terms.front().effect->needs_speed_change();
    if (va != vb) return !va;
    return a.score < b.score;
  };
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    for (std::size_t j = i + 1; j < candidates.size(); ++j) {
      const Candidate& a = candidates[i];
      const Candidate& b = candidates[j];
      if (a.proposed && b.proposed && alike(a, b) && simpler(b, a)) std::swap(candidates[i], candidates[j]);
    }
  }
}

/// A family is the one step that reaches the floor where a smooth pattern spreads
/// over many orders. First only when it does and nothing smaller does: one effect
/// that reaches the floor is the plainer explanation (the family's extra orders may
/// be a converter's quantization pattern at a speed commensurate with the sample
/// rate), and a family that does not reach it is a curve fit, not a finding.
void family_first_only_alone(std::vector<Candidate>& candidates) {
  if (candidates.empty() || !candidates.front().family) return;
  const bool family_explains = candidates.front().reaches_floor;
  const auto smaller = std::find_if(candidates.begin() + 1, candidates.end(), [&](const Candidate& c) {
    return !c.family && c.proposed && (c.reaches_floor || !family_explains);
  });
  if (smaller != candidates.end()) std::rotate(candidates.begin(), smaller, smaller + 1);
}

/// By score, the proposed ones first: a candidate is unproposed below its score where the
/// fit would refuse it beside the model (an alias of its terms: offer_swaps), and the swap
/// that fits it in their place, a little worse by the BIC, is the change to make.
void sort_by_score(std::vector<Candidate>& candidates) {
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    if (a.proposed != b.proposed) return a.proposed;
    return a.score < b.score;
  });
}

}  // namespace

std::vector<ModelTerm> residual_candidate_terms(const ModelFit& fit, const DiscoveryOptions& opt,
                                                std::vector<const Effect*>* answered) {
  std::vector<ModelTerm> out;
  const ModelSpec& spec = fit.model.spec();
  const FitResidualSpectrum residual(fit, fit.account.fitted);
  for (const Effect* e : effect_registry()) {
    if (!e->fittable()) continue;
    const auto sets = e->residual_candidates(residual, opt.harmonic_families);
    if (!sets) continue;
    if (answered != nullptr) answered->push_back(e);
    for (const CandidateParams& set : *sets) {
      const ModelTerm t = set.family ? family_term(*e, spec, set.groups) : listed_term(*e, spec, set.groups.front());
      if (!t.params.empty()) out.push_back(t);
    }
  }
  return out;
}

bool already_listed(const std::vector<Candidate>& candidates, const std::string& effect) {
  return std::any_of(candidates.begin(), candidates.end(), [&](const Candidate& o) { return o.effect == effect; });
}

bool is_family(const ModelTerm& t) { return t.params.size() >= 2 * static_cast<std::size_t>(kFamilyFrom); }

void order_ranked(std::vector<Candidate>& candidates, const DiscoveryOptions& options) {
  for (Candidate& c : candidates) c.fits_as_well.clear();  // ordered again after a refit: listed anew
  sort_by_score(candidates);
  order_alike_simplest_first(candidates, options);
  family_first_only_alone(candidates);
}

namespace {

/// Proposed candidates the pair screen pairs: the best of them as ranked.
constexpr std::size_t kScreenedCandidates = 8;
/// Screened pairs kept: those whose joint step leaves at most this times the best pair's
/// weighted residual (10x in RMS). A step's error is second order in the pair's values,
/// alike for pairs that fit the same residual: a pair that far behind would need it ten
/// times the best pair's whole residual. The right pair of 2 % offsets and a 3 % quadrature
/// under a 10 % imbalance: its step leaves 1/97 of the next pair's, still far above the
/// floor, and its fit reaches the floor (tests/integration/test_real_inputs.py, TwoMissing).
constexpr double kScreenedResidualRatio = 100.0;
/// And those whose step leaves at most this share of what the best candidate alone leaves:
/// a pair that adds less than a fifth is no second effect found (a drifting gain, which no
/// catalog pair describes: the best pairs' steps leave 99.7 % of it, and three fits went for
/// nothing). The true pair of a quadrature and a phased K_3 leaves 53 % of what the
/// mechanical 6x alone leaves, linearised, and reaches the floor fitted.
constexpr double kScreenedGain = 0.8;

}  // namespace

std::vector<ScreenedPair> screen_pairs(const std::vector<Candidate>& ranked,
                                       const std::map<std::string, std::vector<int>>& columns_of,
                                       const std::vector<NormalEquations>& groups, const GroupFloors& floors,
                                       const std::vector<int>& base_cols) {
  std::vector<const Candidate*> pool;
  for (const Candidate& c : ranked) {
    if (pool.size() == kScreenedCandidates) break;
    if (c.proposed && !c.family && c.replaces.empty() && columns_of.count(c.effect) > 0) pool.push_back(&c);
  }
  std::vector<ScreenedPair> scored;
  for (std::size_t i = 0; i < pool.size(); ++i) {
    for (std::size_t j = i + 1; j < pool.size(); ++j) {
      std::vector<int> cols = base_cols;
      for (const Candidate* c : {pool[i], pool[j]}) {
        const std::vector<int>& own = columns_of.at(c->effect);
        cols.insert(cols.end(), own.begin(), own.end());
      }
      const StepSolution s = solve_step(groups, floors, cols);
      if (s.ok) scored.push_back({pool[i]->effect, pool[j]->effect, s.rss_w});
    }
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const ScreenedPair& a, const ScreenedPair& b) { return a.weighted_rss < b.weighted_rss; });
  const double best_alone = ranked.empty() ? 0.0 : ranked.front().weighted_rss;
  const auto kept = std::find_if(scored.begin(), scored.end(), [&](const ScreenedPair& p) {
    return p.weighted_rss > kScreenedResidualRatio * scored.front().weighted_rss ||
           p.weighted_rss > kScreenedGain * best_alone;
  });
  scored.erase(kept, scored.end());
  return scored;
}

Ranking rank_candidates(const PreparedLog& log, const ModelFit& fit, const DiscoveryOptions& options) {
  Ranking out;
  std::vector<ModelTerm> terms = candidate_terms(log, fit, options, out.not_evaluated);
  for (const Effect* e : effect_registry()) {
    if (!e->fittable()) {
      out.not_evaluated.push_back(std::string(e->name()) + ": sets the noise floor, not a candidate");
    }
  }
  if (terms.empty()) return out;
  const GroupFloors floors = fit.floors.floors();
  Design d = design_for(fit.model, log);
  const std::size_t first_candidate = d.terms().size();
  for (const ModelTerm& t : terms) d.add_candidate(t);
  PassStatistics stats(d.columns());
  accumulate(d, log.rows, floors, stats);
  ++out.passes;
  const std::vector<int> base_cols = model_columns(d);
  const StepSolution base = solve_step(stats.all, floors, base_cols);
  std::vector<ModelTerm> unseparated;
  std::map<std::string, std::vector<int>> columns_of;  // each scored candidate's columns (narrowed ones too)
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const std::size_t term = first_candidate + i;
    const std::vector<int> all_cols = term_columns(d, term);
    const ModelTerm asked = terms[i];
    const StepSolution s = solve_candidate(stats.all, floors, base_cols, all_cols, terms[i]);
    if (!s.ok) {
      unseparated.push_back(terms[i]);
      out.not_evaluated.push_back(terms[i].reference() + ": not separable from the model with the signals in this log" +
                                  (log.sincos ? std::string() : std::string(" (sin/cos would tell them apart)")));
      continue;
    }
    const std::string reference = terms[i].reference();
    if (already_listed(out.candidates, reference)) continue;
    std::vector<int>& own = columns_of[reference];
    for (std::size_t k = 0; k < asked.params.size() && k < all_cols.size(); ++k) {
      if (std::find(terms[i].params.begin(), terms[i].params.end(), asked.params[k]) != terms[i].params.end()) {
        own.push_back(all_cols[k]);
      }
    }
    Candidate c;
    c.effect = reference;
    c.family = is_family(terms[i]);
    score_candidate(c, s, log.rd, base, floors, options);
    c.params = term_params(d, term, s, true);
    std::erase_if(c.params, [&](const ModelParameter& pv) {
      for (int p : terms[i].params) {
        if (pv.name == terms[i].param_name(static_cast<std::size_t>(&p - terms[i].params.data()))) return false;
      }
      return true;
    });
    c.reason = reason_of(terms[i], c.params);
    out.candidates.push_back(std::move(c));
    if (options.progress) options.progress(0.5 + 0.3 * static_cast<double>(i + 1) / static_cast<double>(terms.size()));
  }
  // The refits are the first candidates as they are listed (the simplest of those the
  // log cannot tell apart first), as a merge of statistics chooses them
  // (run_statistics.h candidates_to_refit): the same candidates carry exact values.
  order_ranked(out.candidates, options);
  refit_nonlinear(out, log, fit, base, floors, options);
  order_ranked(out.candidates, options);
  for (Candidate& c : out.candidates) flag_one_step(c, options);
  const std::size_t listed = out.candidates.size();
  offer_swaps(out, unseparated, log, fit, base, floors, options);
  if (out.candidates.size() > listed) order_ranked(out.candidates, options);
  out.screened_pairs = screen_pairs(out.candidates, columns_of, stats.all, floors, base_cols);
  return out;
}

namespace {

/// Screened pairs the search fits at most after the others; one where a best candidate is
/// named already (PairSearch::kScreened: does the screen's first pair do better?).
constexpr int kMaxScreenedPairFits = 3;
constexpr int kMaxScreenedPairFitsNamed = 1;
/// Pairs whose steps leave within this share of the first fitted pair's residual are ones
/// the screen cannot order: where two candidates fit the same order of the error
/// linearised (a mechanical 6x and a phased K_3 at p_r = 3, both on 2 theta), their pairs
/// with a quadrature tied to 1e-6 in memory and differed by 0.5 % merged from 2 s chunks,
/// and only the exact fit tells the true one (K_3) from the other. Pairs of different
/// effects lie far apart (the right pair of offsets and a quadrature: 1/97 of the next).
constexpr double kScreenTie = 0.05;

}  // namespace

bool fits_next_screened(int fits, PairSearch search, double rss, double first_rss) {
  if (fits >= kMaxScreenedPairFits) return false;
  if (search == PairSearch::kEvery || fits < kMaxScreenedPairFitsNamed) return true;
  return rss <= (1.0 + kScreenTie) * first_rss;
}

namespace {

/// Whether the log cannot tell `a` from `b` (either lists the other: Candidate::fits_as_well).
bool told_alike(const Candidate& a, const Candidate& b) {
  const auto lists = [](const Candidate& x, const std::string& e) {
    return std::find(x.fits_as_well.begin(), x.fits_as_well.end(), e) != x.fits_as_well.end();
  };
  return lists(a, b.effect) || lists(b, a.effect);
}

/// Pairs beyond the best three the two-effect search fits at most (each a fit of the whole
/// log: only where no pair of the best three explains it).
constexpr int kMaxAlikePairFits = 9;
/// Members of each of the three best classes of alike candidates the search pairs.
constexpr std::size_t kAlikeClassMembers = 3;

/// Whether the model with both candidates added explains the log (an exact fit of it).
using PairExplains = std::function<bool(const Candidate&, const Candidate&)>;


/// The first explaining pair of the best three, then across the best classes of alike
/// candidates (find_missing_pair).
std::vector<std::string> best_or_alike_pair(const std::vector<const Candidate*>& pool, const PairExplains& explains) {
  const std::size_t best = std::min<std::size_t>(pool.size(), 3);
  for (std::size_t i = 0; i < best; ++i) {
    for (std::size_t j = i + 1; j < best; ++j) {
      if (explains(*pool[i], *pool[j])) return {pool[i]->effect, pool[j]->effect};
    }
  }
  // Candidates the log cannot tell apart score alike at first order, and the one a linearised
  // step ranks first may be the wrong one at second order, where the pair's exact fit differs
  // (an R/D angle alone at p_r = 1: offsets beside eccentricity, quadrature beside a
  // mechanical 2x). So the members of the three best classes of alike candidates pair across
  // classes too, the pairs of the best-ranked members first. A candidate in place of a model
  // term (Candidate::replaces) is not an addition.
  std::vector<int> cls(pool.size(), -1);
  std::vector<std::size_t> members;
  int classes = 0;
  for (std::size_t i = 0; i < pool.size(); ++i) {
    for (std::size_t j = 0; j < i && cls[i] < 0; ++j) {
      if (told_alike(*pool[i], *pool[j])) cls[i] = cls[j];
    }
    if (cls[i] < 0) cls[i] = classes++;
    if (cls[i] >= 3 || !pool[i]->replaces.empty()) continue;
    const auto in_class = std::count_if(members.begin(), members.end(), [&](std::size_t m) { return cls[m] == cls[i]; });
    if (static_cast<std::size_t>(in_class) < kAlikeClassMembers) members.push_back(i);
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t a = 0; a < members.size(); ++a) {
    for (std::size_t b = a + 1; b < members.size(); ++b) {
      const std::size_t i = members[a], j = members[b];
      if (cls[i] != cls[j] && j >= best) pairs.emplace_back(i, j);
    }
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) { return x.first + x.second < y.first + y.second; });
  if (pairs.size() > static_cast<std::size_t>(kMaxAlikePairFits)) pairs.resize(kMaxAlikePairFits);
  for (const auto& [i, j] : pairs) {
    if (explains(*pool[i], *pool[j])) return {pool[i]->effect, pool[j]->effect};
  }
  return {};
}

/// Pairs the search has fitted.
using TriedPairs = std::vector<std::pair<const Candidate*, const Candidate*>>;

/// Whether the pair `a` + `b` is one tried, or the same but for members the log cannot tell
/// apart (told_alike): those the alike classes' search chose among already.
bool tried_or_alike(const Candidate& a, const Candidate& b, const TriedPairs& tried) {
  const auto same = [](const Candidate& x, const Candidate& y) { return x.effect == y.effect || told_alike(x, y); };
  return std::any_of(tried.begin(), tried.end(), [&](const auto& t) {
    return (same(a, *t.first) && same(b, *t.second)) || (same(a, *t.second) && same(b, *t.first));
  });
}

/// The first explaining pair of the screened pairs not `tried` (tried_or_alike) that
/// fits_next_screened lets the search fit.
std::vector<std::string> screened_pair(const std::vector<const Candidate*>& pool, std::span<const ScreenedPair> screened,
                                       const TriedPairs& tried, PairSearch search, const PairExplains& explains) {
  // Last, the pairs whose joint linearised step fits best, wherever each ranks alone: two
  // effects that share an order of the error (offsets 2 % and a 3 % quadrature under a 10 %
  // imbalance) each take part of the other's signature, so the second ranks below the
  // aliases of the first and outside the classes above.
  const auto in_pool = [&](const std::string& e) -> const Candidate* {
    const auto it = std::find_if(pool.begin(), pool.end(), [&](const Candidate* c) { return c->effect == e; });
    return it == pool.end() ? nullptr : *it;
  };
  int fits = 0;
  double first_rss = 0.0;
  for (const ScreenedPair& p : screened) {
    const Candidate* ca = in_pool(p.a);
    const Candidate* cb = in_pool(p.b);
    if (ca == nullptr || cb == nullptr || tried_or_alike(*ca, *cb, tried)) continue;
    if (fits == 0) first_rss = p.weighted_rss;
    if (!fits_next_screened(fits, search, p.weighted_rss, first_rss)) break;
    ++fits;
    if (explains(*ca, *cb)) return {p.a, p.b};
  }
  return {};
}

}  // namespace

std::vector<std::string> find_missing_pair(const PreparedLog& log, const ModelFit& fit,
                                           const std::vector<Candidate>& candidates, const DiscoveryOptions& options,
                                           std::span<const ScreenedPair> screened, PairSearch search) {
  // Effects, not families: a pair is two findings, a family already many orders.
  std::vector<const Candidate*> pool;
  for (const Candidate& c : candidates) {
    if (c.proposed && !c.family) pool.push_back(&c);
  }
  TriedPairs tried;
  const auto explains = [&](const Candidate& a, const Candidate& b) {
    tried.emplace_back(&a, &b);
    std::vector<std::string> refs = fit.model.spec().references();
    refs.push_back(a.effect);
    refs.push_back(b.effect);
    try {
      return fit_prepared(log, refs, options).explained;
    } catch (const std::invalid_argument&) {
      return false;  // not separable together: not the pair
    }
  };
  if (search == PairSearch::kEvery) {
    if (std::vector<std::string> found = best_or_alike_pair(pool, explains); !found.empty()) return found;
  }
  return screened_pair(pool, screened, tried, search, explains);
}

}  // namespace resolver
