#include "tools/model/merge_report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "tools/model/json_text.h"
#include "tools/model/model_report.h"

namespace resolver {

namespace {

std::string unit_of(const SignalResidual& s) {
  return s.signal == "position_error" ? " rad" : s.signal == "i_dq" ? " A" : " of the amplitude";
}

std::string json_params(const std::vector<ModelParameter>& ps) {
  std::string o = "{";
  for (std::size_t i = 0; i < ps.size(); ++i) {
    o += fmt::format("{}{}:{{\"value\":{},\"stderr\":{},\"unit\":{}}}", i > 0 ? "," : "", json::str(ps[i].name),
                     json::num(ps[i].value), json::num(ps[i].std_error), json::str(ps[i].unit));
  }
  return o + "}";
}

std::string json_strings(const std::vector<std::string>& v) {
  std::string o = "[";
  for (std::size_t i = 0; i < v.size(); ++i) o += (i > 0 ? "," : "") + json::str(v[i]);
  return o + "]";
}

}  // namespace

MergeVerdict merge_verdict(const MergedFit& m, double explained_ratio) {
  const std::string ratio = fmt::format("{:.3g}", explained_ratio);
  if (m.explained) {
    return {"explained", "every signal's residual is within " + ratio +
                             "x its pooled noise floor, on held-back samples too (linearised, from the statistics)"};
  }
  if (m.untrusted) {
    return {"unexplained", "the signals are faulty for a large part of a run (see the notes): a fit on them says "
                           "nothing about the resolver, and no effect is proposed; fix the input and record again"};
  }
  // As explain: where the model is at the floor without the outliers, they are the finding.
  bool in_sample = !m.signals.empty(), outliers_matter = false;
  double worst = 0.0;
  for (const SignalResidual& r : m.signals) {
    in_sample = in_sample && r.rms <= explained_ratio * r.floor;
    outliers_matter = outliers_matter || (m.outlier_samples > 0 && r.rms_with_outliers > explained_ratio * r.floor);
    worst = std::max(worst, r.rms_with_outliers / r.floor);
  }
  if (outliers_matter && in_sample) {
    return {"unexplained", fmt::format("{} impulsive samples (outliers) carry the residual to {:.1f}x the floor; without "
                                       "them the model explains the runs. Find their source (EMI, bit errors) before "
                                       "trusting a fit; they are kept out of this one.",
                                       m.outlier_samples, worst)};
  }
  if (!m.linearised.empty()) {
    return {"unexplained", fmt::format("not judged: {} only linearised from zero in these statistics (see the note); "
                                       "make the statistics with the model in --effects and merge again",
                                       fmt::join(m.linearised, ", "))};
  }
  if (m.missing_pair.size() == 2) {
    std::vector<std::string> values;
    for (const ModelParameter& p : m.missing_pair_params) {
      values.push_back(fmt::format("{} = {:.3g} +- {:.2g}", p.name, p.value, p.std_error));
    }
    // As explain's pair (model_discovery.cpp): named only when the two together reach the floor.
    return {"missing_effect",
            fmt::format("two effects are missing: {} and {} together bring every signal to within {}x its pooled "
                        "floor, on held-back samples too (neither does alone). Fitted to convergence on every run "
                        "(the statistics made again with both in the model): {}.",
                        m.missing_pair[0], m.missing_pair[1], ratio, fmt::join(values, ", "))};
  }
  const Candidate* best = m.candidates.empty() || !m.candidates.front().proposed ? nullptr : &m.candidates.front();
  std::int64_t rows = 0;
  for (const SignalResidual& r : m.signals) rows += r.rows;
  // explain's rule (model_discovery.cpp): named when it reaches the floor or removes most
  // of what lies above it.
  if (best != nullptr && (best->reaches_floor || removes_most_excess(m.signals, rows, m.rd, best->weighted_rss))) {
    const bool exact = std::find(m.refitted.begin(), m.refitted.end(), best->effect) != m.refitted.end();
    const bool linear = !best->stepped;
    const bool held = std::find(m.held.begin(), m.held.end(), best->effect) != m.held.end();
    return {"missing_effect",
            best->change() +
                (best->reaches_floor ? " brings every signal to within " + ratio + "x its floor: "
                                     : " removes most of the residual above the floor: ") +
                best->reason +
                (exact && held ? " Fitted to convergence by Gauss-Newton over passes of the logs (the statistics made "
                                 "again with it in the model; runs whose rows alone cannot separate it hold it at the "
                                 "merged value)."
                 : exact  ? " Fitted to convergence on every run (the statistics made again with it in the model)."
                 : linear ? " Its parameters enter linearly: the step from the statistics is its fit."
                          : " Its value is one step linearised from zero: make the statistics again with it in "
                            "--effects (or fit the logs) for the exact fit.") +
                (m.pair_search_skipped && !best->reaches_floor
                     ? " It does not reach the floor, and two effects together may (see the note): "
                       "not searched without the logs."
                     : "")};
  }
  return {"unexplained", best == nullptr ? "no candidate in the statistics lowers the residual enough to be proposed"
                                         : "the best candidate, " + best->effect +
                                               ", does not bring the residual near the floor: run resolver-model "
                                               "explain on the logs"};
}

std::string format_merge_text(const MergedFit& m, const std::vector<std::string>& runs,
                              const std::vector<RunStatistics>& stats, double explained_ratio) {
  std::string o = fmt::format("merged {} run{} ({} fitted samples)\n", m.runs, m.runs == 1 ? "" : "s", m.rows);
  for (std::size_t r = 0; r < runs.size(); ++r) {
    o += fmt::format("  {}: {} fitted samples over {:.3g} s, {:.3g} electrical revolutions; its model {}\n", runs[r],
                     stats[r].fitted_rows, stats[r].span_s, stats[r].electrical_revolutions,
                     fmt::join(stats[r].effects, ", "));
  }
  o += fmt::format("model: {}\n", m.effects.empty() ? std::string("(none)") : fmt::format("{}", fmt::join(m.effects, ", ")));
  for (const std::string& n : m.notes) o += "note: " + n + "\n";
  o += "\nparameters (value +- standard error):\n";
  for (const ModelParameter& p : m.params) {
    o += fmt::format("  {:<36} {:>12.7g} +- {:.2g} {}\n", p.name, p.value, p.std_error, p.unit);
  }
  if (!m.comparisons.empty()) o += "\neach run's own fit against the others' (* = disagrees: |z| > 4):\n";
  for (const PoolDisagreement& d : m.comparisons) {
    o += fmt::format("  {} {:<20} {:<30} {:>12.6g} +- {:.2g} against {:.6g} +- {:.2g} (z = {:.1f})\n",
                     std::abs(d.z) > kPoolDisagreementZ ? '*' : ' ', d.log, d.parameter, d.value, d.std_error,
                     d.others, d.others_std_error, d.z);
  }
  o += "\neach run's constants:\n";
  for (const ModelParameter& p : m.nuisance) o += fmt::format("  {:<36} {:>12.5g}\n", p.name, p.value);
  o += "\nresidual rms vs the pooled noise floor (held back: fitted on one fold, evaluated on the other):\n";
  for (const SignalResidual& s : m.signals) {
    o += fmt::format("  {:<15} {:.3g}{} (before: {:.3g}), floor {:.3g} -> {:.2f}x floor; held back {}\n", s.signal,
                     s.rms, unit_of(s), s.raw_rms, s.floor, s.rms / s.floor,
                     std::isfinite(s.held_back_rms) ? fmt::format("{:.2f}x", s.held_back_rms / s.floor) : "n/a");
  }
  o += m.candidates.empty() ? "\ncandidates: none in every run's statistics\n"
                            : "\ncandidates (lowest BIC first; * = proposed; ERR = share of the residual it removes):\n";
  for (const Candidate& c : m.candidates) {
    o += fmt::format("  {} {:<26} BIC drop {:.1f} ERR {:.3f}{}\n      {}\n", c.proposed ? '*' : ' ', c.effect,
                     c.bic_drop, c.err, c.reaches_floor ? "  reaches the floor" : "", c.reason);
    if (c.stepped) o += std::string(kOneStepNote);
  }
  for (const std::string& n : m.not_evaluated) o += "    not evaluated: " + n + "\n";
  const MergeVerdict v = merge_verdict(m, explained_ratio);
  return o + fmt::format("\nverdict: {}\n{}\n", v.word, v.summary);
}

std::string format_merge_json(const MergedFit& m, const std::vector<std::string>& runs,
                              const std::vector<RunStatistics>& stats, double explained_ratio) {
  std::string o = "{\"runs\":[";
  for (std::size_t r = 0; r < runs.size(); ++r) {
    o += fmt::format("{}{{\"file\":{},\"fitted_samples\":{},\"span_s\":{},\"effects\":{}}}", r > 0 ? "," : "",
                     json::str(runs[r]), stats[r].fitted_rows, json::num(stats[r].span_s), json_strings(stats[r].effects));
  }
  o += "],\"effects\":" + json_strings(m.effects) + ",\"params\":" + json_params(m.params) +
       ",\"nuisance\":" + json_params(m.nuisance) + ",\"signals\":[";
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    const SignalResidual& s = m.signals[i];
    o += fmt::format("{}{{\"signal\":{},\"rms\":{},\"raw_rms\":{},\"floor\":{},\"held_back_rms\":{},\"rows\":{}}}",
                     i > 0 ? "," : "", json::str(s.signal), json::num(s.rms), json::num(s.raw_rms), json::num(s.floor),
                     json::num(s.held_back_rms), s.rows);
  }
  o += "],\"candidates\":[";
  for (std::size_t i = 0; i < m.candidates.size(); ++i) {
    const Candidate& c = m.candidates[i];
    o += fmt::format("{}{{\"effect\":{},\"bic_drop\":{},\"err\":{},\"proposed\":{},\"reaches_floor\":{},"
                     "\"one_step\":{},\"reason\":{},\"params\":{}}}",
                     i > 0 ? "," : "", json::str(c.effect), json::num(c.bic_drop), json::num(c.err), c.proposed,
                     c.reaches_floor, c.stepped, json::str(c.reason), json_params(c.params));
  }
  o += "],\"comparisons\":[";
  for (std::size_t i = 0; i < m.comparisons.size(); ++i) {
    const PoolDisagreement& d = m.comparisons[i];
    o += fmt::format("{}{{\"run\":{},\"parameter\":{},\"value\":{},\"std_error\":{},\"others\":{},"
                     "\"others_std_error\":{},\"z\":{},\"disagrees\":{}}}",
                     i > 0 ? "," : "", json::str(d.log), json::str(d.parameter), json::num(d.value),
                     json::num(d.std_error), json::num(d.others), json::num(d.others_std_error), json::num(d.z),
                     std::abs(d.z) > kPoolDisagreementZ);
  }
  const MergeVerdict v = merge_verdict(m, explained_ratio);
  o += "],\"missing_pair\":" + json_strings(m.missing_pair) + ",\"missing_pair_params\":" +
       json_params(m.missing_pair_params);
  o += ",\"not_evaluated\":" + json_strings(m.not_evaluated) + ",\"notes\":" + json_strings(m.notes) +
       ",\"verdict\":" + json::str(v.word) + ",\"summary\":" + json::str(v.summary) + "}\n";
  return o;
}

}  // namespace resolver
