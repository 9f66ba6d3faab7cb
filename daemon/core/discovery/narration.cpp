#include "daemon/core/discovery/narration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/angles.h"
#include "daemon/core/discovery/fit_support.h"
#include "daemon/core/model/custom_effect.h"
#include "daemon/core/model/least_squares.h"

namespace resolver {

namespace {

constexpr double kSignificance = 4.0;  // standard errors of a harmonic amplitude

std::string unit_of(const std::string& signal, double v) {
  if (signal == "position_error") return " rad (" + num(rad_to_arcmin(v)) + " arcmin)";
  if (signal == "i_dq") return " A";
  return " of the amplitude";
}

std::string phase_words(const HarmonicResidual& x) {
  if (x.order == 0) return "";
  const double deg = std::fmod(std::abs(rad_to_deg(x.phase)), 180.0);
  if (deg < 20.0 || deg > 160.0) return " (in phase with sin)";
  if (std::abs(deg - 90.0) < 20.0) return " (in phase with cos)";
  return " (phase " + num(rad_to_deg(x.phase), "%.0f") + " deg)";
}

std::string harmonic_list(const std::vector<HarmonicResidual>& h, double threshold, const char* angle) {
  std::vector<HarmonicResidual> v = h;
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.amplitude > b.amplitude; });
  std::string out;
  for (const HarmonicResidual& x : v) {
    if (x.amplitude < threshold || out.size() > 200) break;
    out += (out.empty() ? "" : ", ") +
           (x.order == 0 ? std::string("constant") : std::to_string(x.order) + " " + angle) + " " + num(x.amplitude) +
           phase_words(x);
  }
  return out;
}

double amplitude_se(const ModelFit& fit) {
  return fit.noise_floor_rad * std::sqrt(2.0 / std::max<double>(1.0, static_cast<double>(fit.account.fitted)));
}

std::vector<int> top_orders(const std::vector<HarmonicResidual>& h, double se, int lowest, std::size_t count) {
  std::vector<HarmonicResidual> v;
  for (const HarmonicResidual& x : h) {
    if (x.order >= lowest && x.amplitude > kSignificance * se) v.push_back(x);
  }
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.amplitude > b.amplitude; });
  std::vector<int> out;
  for (std::size_t i = 0; i < v.size() && i < count; ++i) out.push_back(v[i].order);
  return out;
}

std::string harmonic_term(const char* fn, int k, const char* angle) {
  return k == 1 ? fmt::format("{}({})", fn, angle) : fmt::format("{}({}*{})", fn, k, angle);
}

bool varies(double lo, double hi, double floor, double ratio) { return hi > ratio * floor && hi > 1.5 * lo; }

}  // namespace

std::vector<std::string> describe_failure(const PreparedLog& log, const ModelFit& fit, double ratio) {
  std::vector<std::string> out;
  for (const OutlierSignal& o : fit.outliers) {
    std::string times;
    for (double t : o.times) times += (times.empty() ? "" : ", ") + num(t, "%.4g");
    double with = 0.0;
    for (const SignalResidual& s : fit.signals) {
      if (s.signal == o.signal || (o.signal == "sin_cos" && s.signal == "sin_cos")) with = s.rms_with_outliers / s.floor;
    }
    out.push_back(fmt::format("outliers: {} impulsive samples on {} (largest {}{}, at {} s{}): kept out of the fit "
                              "and the floor; the residual including them is {}x the floor",
                              o.count, o.signal, num(o.largest), unit_of(o.signal, o.largest), times,
                              o.count > static_cast<std::int64_t>(o.times.size()) ? ", ..." : "", num(with, "%.1f")));
  }
  for (const SignalResidual& s : fit.signals) {
    if (s.rms > ratio * s.floor) {
      out.push_back(s.signal + ": residual " + num(s.rms) + unit_of(s.signal, s.rms) + " is " +
                    num(s.rms / s.floor, "%.1f") + "x the noise floor " + num(s.floor));
    } else if (std::isfinite(s.held_back_rms) && s.held_back_rms > ratio * s.floor) {
      out.push_back(s.signal + ": fits the samples it saw (" + num(s.rms / s.floor, "%.2f") +
                    "x floor) but not the held-back ones (" + fit.account.fold_rule + ": " +
                    num(s.held_back_rms / s.floor, "%.2f") +
                    "x floor): the model does not carry over between the folds");
    }
  }
  const bool position_fails = !fit.signals.empty() && fit.signals.front().rms > ratio * fit.signals.front().floor;
  const double threshold = std::max(0.2 * fit.noise_floor_rad, kSignificance * amplitude_se(fit));
  if (position_fails) {
    const std::string hs = harmonic_list(fit.harmonics, threshold, "theta");
    const std::string ms = harmonic_list(fit.harmonics_mech, threshold, "theta_m");
    if (!hs.empty()) out.push_back("position-error residual by harmonic of theta: " + hs + " rad");
    if (!ms.empty()) out.push_back("by harmonic of the mechanical angle theta_m: " + ms + " rad");
    if (hs.empty() && ms.empty()) {
      out.push_back("position-error residual is not locked to the angle (no harmonic of theta or theta_m above a "
                    "fifth of the floor)");
    }
  }
  for (const SignalResidual& s : fit.signals) {
    if (s.signal != "i_dq" || s.rms <= ratio * s.floor) continue;
    std::string cs;
    for (std::size_t k = 1; k < fit.harmonics_id.size() && k < fit.harmonics_iq.size(); ++k) {
      const double ad = fit.harmonics_id[k].amplitude, aq = fit.harmonics_iq[k].amplitude;
      if (std::max(ad, aq) < 0.2 * s.floor) continue;
      cs += (cs.empty() ? "" : ", ") + std::to_string(k) + " theta_e: i_d " + num(ad) + " A, i_q " + num(aq) + " A";
    }
    out.push_back(cs.empty() ? "i_dq residual is not locked to theta_e (no harmonic above a fifth of the floor)"
                             : "i_dq residual by harmonic of theta_e: " + cs);
  }
  if (!position_fails) return out;
  const double floor = fit.noise_floor_rad;
  if (fit.directions.size() == 2) {
    const DirectionResidual& f = fit.directions[0].direction > 0 ? fit.directions[0] : fit.directions[1];
    const DirectionResidual& b = fit.directions[0].direction > 0 ? fit.directions[1] : fit.directions[0];
    const double se = floor * std::sqrt(1.0 / std::max<double>(1, static_cast<double>(f.samples)) +
                                        1.0 / std::max<double>(1, static_cast<double>(b.samples)));
    if (std::abs(f.mean - b.mean) > kSignificance * se && std::abs(f.mean - b.mean) > 0.5 * floor) {
      out.push_back(fmt::format("by direction: the residual's mean is {} rad forward and {} rad backward: an offset "
                                "that flips with the direction (backlash, or a delay at this speed)",
                                num(f.mean), num(b.mean)));
    }
  }
  // On one turn at one speed time and angle are the same axis (t is an affine function
  // of theta_m): a drift term would be a mechanical harmonic in disguise. Two turns
  // apart tell them apart.
  const bool time_is_not_angle = log.motion.travelled >= 2.0 * kTwoPi;
  if (fit.time_bins.size() > 1 && time_is_not_angle) {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    std::string ts;
    for (const TimeBinResidual& b : fit.time_bins) {
      lo = std::min(lo, b.rms);
      hi = std::max(hi, b.rms);
      ts += (ts.empty() ? "" : ", ") + num(b.t_lo) + "-" + num(b.t_hi) + " s: " + num(b.rms / floor, "%.1f") + "x";
    }
    if (varies(lo, hi, floor, ratio)) {
      out.push_back("the residual changes over time (" + ts +
                    " the floor): no catalog effect depends on time (a drift, e.g. with temperature, is outside "
                    "the catalog)");
    }
  }
  if (fit.speed_bins.size() > 1) {
    std::string bs;
    for (const SpeedBinResidual& b : fit.speed_bins) {
      bs += (bs.empty() ? "" : ", ") + num(b.rpm_mid, "%.0f") + " r/min: " + num(b.rms / floor, "%.1f") + "x";
    }
    out.push_back("by speed: " + bs + " the floor");
  }
  if (fit.floors.rd.source == "standstill" && fit.floors.rd.second_difference > 3.0 * fit.floors.rd.standstill) {
    out.push_back(fmt::format("the moving samples' own noise ({} rad, second differences) is {:.1f}x the sensor's "
                              "noise at standstill ({} rad): noise that only motion makes (timing jitter between "
                              "the resolver and the reference?) or structure faster than 16 theta",
                              num(fit.floors.rd.second_difference),
                              fit.floors.rd.second_difference / fit.floors.rd.standstill, num(fit.floors.rd.standstill)));
  }
  (void)log;
  return out;
}

namespace {

/// The terms a suggestion chooses from: the residual's strongest harmonics of theta and
/// theta_m, a constant, their modulations by time and speed, and sign(omega).
std::vector<std::string> term_dictionary(const PreparedLog& log, const ModelFit& fit, const DiscoveryOptions& options) {
  const double se = amplitude_se(fit);
  const double floor = fit.noise_floor_rad;
  std::vector<std::string> dict;
  const std::vector<int> theta_orders = top_orders(fit.harmonics, se, 1, 4);
  for (int k : theta_orders) {
    dict.push_back(harmonic_term("sin", k, "theta"));
    dict.push_back(harmonic_term("cos", k, "theta"));
  }
  if (log.reference) {
    for (int k : top_orders(fit.harmonics_mech, se, 1, 3)) {
      if (k % log.p_r == 0) continue;  // order k of theta_m is order k / p_r of theta: already in the list
      dict.push_back(harmonic_term("sin", k, "theta_m"));
      dict.push_back(harmonic_term("cos", k, "theta_m"));
    }
    if (!fit.harmonics.empty() && fit.harmonics.front().amplitude > kSignificance * se) dict.emplace_back("1");
  }
  // A modulation (by time or speed) of the resolver's most common error, 2 theta,
  // and of the residual's strongest order: a drift of alpha averages out of the
  // residual's harmonics but not out of t*sin(2 theta).
  std::vector<int> modulated_orders{2};
  if (!theta_orders.empty() && theta_orders.front() != 2) modulated_orders.push_back(theta_orders.front());
  auto modulated = [&](const std::string& by) {
    dict.push_back(by);
    for (int k : modulated_orders) {
      dict.push_back(by + "*" + harmonic_term("sin", k, "theta"));
      dict.push_back(by + "*" + harmonic_term("cos", k, "theta"));
    }
  };
  // On one turn at one speed time and angle are the same axis (t is an affine function
  // of theta_m): a drift term would be a mechanical harmonic in disguise. Two turns
  // apart tell them apart.
  const bool time_is_not_angle = log.motion.travelled >= 2.0 * kTwoPi;
  if (fit.time_bins.size() > 1 && time_is_not_angle) {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0, mlo = lo, mhi = -lo;
    for (const TimeBinResidual& b : fit.time_bins) {
      lo = std::min(lo, b.rms);
      hi = std::max(hi, b.rms);
      mlo = std::min(mlo, b.mean);
      mhi = std::max(mhi, b.mean);
    }
    if (varies(lo, hi, floor, options.explained_ratio) || mhi - mlo > floor) modulated("t");
  }
  if (fit.speed_bins.size() > 1 && log.reference) {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (const SpeedBinResidual& b : fit.speed_bins) {
      lo = std::min(lo, b.rms);
      hi = std::max(hi, b.rms);
    }
    if (varies(lo, hi, floor, options.explained_ratio)) modulated("omega");
  }
  if (fit.directions.size() == 2 && log.reference) dict.emplace_back("sign(omega)");
  return dict;
}

/// One [[model.custom]] block of a suggestion.
struct SuggestedBlock {
  std::string name, signal;
  std::vector<std::string> terms;
};

/// The position-error block of the whole dictionary and, when the sin/cos signal fails
/// too, the envelopes: a time- or speed-varying gain or phase of the fundamental (a
/// drifting alpha is a gain of the cos channel: t*cos(theta) on cos) that no
/// position-error term describes.
std::vector<SuggestedBlock> candidate_blocks(const PreparedLog& log, const ModelFit& fit,
                                             const DiscoveryOptions& options, const std::string& name,
                                             const std::vector<std::string>& dict) {
  std::vector<SuggestedBlock> blocks{{name, "position_error", dict}};
  bool sincos_fails = false;
  for (const SignalResidual& r : fit.signals) {
    if (r.signal == "sin_cos" && r.rms > options.explained_ratio * r.floor) sincos_fails = true;
  }
  if (sincos_fails && log.sincos) {
    std::vector<std::string> by;
    for (const std::string& d : dict) {
      if (d == "t" || d == "omega") by.push_back(d);
    }
    // The cos channel against the sin channel: its gain and its phase (a common
    // gain is the amplitude, a common rotation a position error: covered already).
    SuggestedBlock env{name + "_cos", "cos", {}};
    for (const std::string& m : by) {
      env.terms.push_back(m + "*cos(theta)");
      env.terms.push_back(m + "*sin(theta)");
    }
    if (!env.terms.empty()) blocks.push_back(std::move(env));
  }
  return blocks;
}

/// Forward selection on one pass of sufficient statistics: the model's columns
/// plus every dictionary term's, accumulated once; then, term by term, the one
/// that lowers the weighted residual most joins, while it lowers the BIC by more
/// than 10 (Kass & Raftery: very strong evidence). Collinear terms (a cos-gain drift
/// is also t sin 2theta in the angle) never both join.
/// Per block (those with terms), which terms joined; nullopt when the model alone has no solution.
std::optional<std::vector<std::vector<bool>>> select_terms(const PreparedLog& log, const ModelFit& fit,
                                                           const std::vector<SuggestedBlock>& blocks) {
  std::vector<CustomEffectSpec> specs;
  for (const SuggestedBlock& bl : blocks) {
    if (!bl.terms.empty()) specs.push_back({bl.name, bl.signal, bl.terms, "suggested by resolver-model explain", "suggestion"});
  }
  const CustomEffects customs(specs);
  Design d = fit.model.design(nuisances_for(log));
  const std::size_t first = d.terms().size();
  for (const auto& c : customs.all()) {
    std::vector<int> all_params;
    for (int i = 0; i < static_cast<int>(c->params().size()); ++i) all_params.push_back(i);
    d.add_candidate(ModelTerm{c.get(), all_params});
  }
  const GroupFloors floors = fit.floors.floors();
  PassStatistics stats(d.columns());
  accumulate(d, log.rows, floors, stats);
  std::vector<int> chosen = model_columns(d);
  StepSolution current = solve_step(stats.all, floors, chosen);
  if (!current.ok) return std::nullopt;
  std::vector<std::vector<bool>> keep(customs.all().size());
  for (std::size_t bi = 0; bi < customs.all().size(); ++bi) keep[bi].assign(customs.all()[bi]->params().size(), false);
  for (;;) {
    int best_col = -1;
    std::size_t best_block = 0, best_term = 0;
    StepSolution best;
    for (std::size_t bi = 0; bi < customs.all().size(); ++bi) {
      const std::vector<int> cols = term_columns(d, first + bi);
      for (std::size_t ti = 0; ti < cols.size(); ++ti) {
        if (keep[bi][ti]) continue;
        std::vector<int> with = chosen;
        with.push_back(cols[ti]);
        const StepSolution s = solve_step(stats.all, floors, with);
        if (!s.ok) continue;
        if (best_col < 0 || s.rss_w < best.rss_w) {
          best_col = cols[ti];
          best_block = bi;
          best_term = ti;
          best = s;
        }
      }
    }
    if (best_col < 0 || bic_of(current) - bic_of(best) <= 10.0) break;
    chosen.push_back(best_col);
    keep[best_block][best_term] = true;
    current = best;
  }
  return keep;
}

/// The blocks as TOML, each with the terms that joined; blocks left without terms are left out.
std::string custom_blocks_toml(std::vector<SuggestedBlock> blocks, const std::vector<std::vector<bool>>& keep,
                               const ModelFit& fit) {
  for (std::size_t bi = 0; bi < blocks.size() && bi < keep.size(); ++bi) {
    std::vector<std::string> kept;
    for (std::size_t ti = 0; ti < blocks[bi].terms.size(); ++ti) {
      if (keep[bi][ti]) kept.push_back(blocks[bi].terms[ti]);
    }
    blocks[bi].terms = kept;
  }
  std::string toml;
  for (const SuggestedBlock& bl : blocks) {
    const std::vector<std::string>& kept = bl.terms;
    if (kept.empty()) continue;
    toml += fmt::format(
        "{}[[model.custom]]\n"
        "name = \"{}\"\n"
        "signal = \"{}\"\n"
        "description = \"residual of {} described by resolver-model explain\"\n"
        "terms = [",
        toml.empty() ? "" : "\n", bl.name, bl.signal, fmt::join(fit.effects, " + "));
    for (std::size_t i = 0; i < kept.size(); ++i) toml += (i == 0 ? "\"" : ", \"") + kept[i] + "\"";
    toml += "]\n";
  }
  return toml;
}

}  // namespace

std::string suggest_custom(const PreparedLog& log, const ModelFit& fit, const DiscoveryOptions& options,
                           const std::string& name) {
  const std::vector<std::string> dict = term_dictionary(log, fit, options);
  if (dict.empty()) return "";
  const std::vector<SuggestedBlock> blocks = candidate_blocks(log, fit, options, name, dict);
  const auto keep = select_terms(log, fit, blocks);
  if (!keep) return "";
  return custom_blocks_toml(blocks, *keep, fit);
}

}  // namespace resolver
