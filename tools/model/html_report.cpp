#include "tools/model/html_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "daemon/core/angles.h"
#include "tools/model/html_page.h"
#include "tools/model/report_assets.h"
#include "tools/model/report_data.h"

namespace resolver {

namespace {

using html::escape;
using html::num_cell;
using html::table;

std::string g3(double v) { return std::isfinite(v) ? fmt::format("{:.3g}", v) : std::string("–"); }
std::string ratio(double v) { return std::isfinite(v) ? fmt::format("{:.2f}x", v) : std::string("–"); }

std::string list(const std::vector<std::string>& items) {
  std::string o = "<ul>";
  for (const auto& s : items) o += "<li>" + escape(s) + "</li>";
  return o + "</ul>\n";
}

/// Unit of each fitted signal as the tables show it.
std::string signal_unit(std::string_view signal) {
  if (signal == "position_error") return "rad";
  if (signal == "i_dq") return "A";
  return "1 (fraction of the amplitude)";
}

std::string signal_value(std::string_view signal, double v) {
  if (signal == "position_error" && std::isfinite(v)) return fmt::format("{:.3g} rad = {:.3g} arcmin", v, rad_to_arcmin(v));
  return g3(v) + (signal == "i_dq" ? " A" : "");
}

// ---- words -------------------------------------------------------------------------------

std::string verdict_words(const DiscoveryRun& run, double explained_ratio) {
  const Explanation& first = run.steps.front();
  const Explanation& last = run.steps.back();
  const auto added = added_effects(first.fit, last.fit);
  const std::string added_text =
      added.empty() ? std::string()
                    : fmt::format(" after adding {} to {}", fmt::join(added, " and "), model_name(first.fit));
  switch (last.verdict) {
    case Verdict::kExplained:
      return fmt::format(
          "Explained: the model {} accounts for every signal in this log to within {}x its noise floor{}.",
          model_name(last.fit), g3(explained_ratio),
          added.empty() ? "; the starting model needed nothing more" : added_text);
    case Verdict::kMissingEffect:
      return fmt::format("Not finished: after {} step{} the model {} still misses an effect ({}).", run.steps.size(),
                         run.steps.size() == 1 ? "" : "s", model_name(last.fit), run.stopped);
    case Verdict::kUnexplained:
      break;
  }
  return fmt::format(
      "Unexplained: no effect in the catalog brings the residual of {} near the noise floor{}; the residual "
      "is described below instead of naming an effect.",
      model_name(last.fit), added_text);
}

// ---- tables ------------------------------------------------------------------------------

std::string coverage_table(const ModelFit& f) {
  const SampleAccount& a = f.account;
  auto row = [](const std::string& what, const std::string& value, const std::string& unit) {
    return std::vector<std::string>{escape(what), num_cell(value), escape(unit)};
  };
  const std::vector<std::vector<std::string>> rows = {
      row("samples in the log", std::to_string(a.samples_in), "samples"),
      row("with an angle (and the reference, when the fit uses one): rows", std::to_string(a.rows), "samples"),
      row("fitted: moving, not outliers, not excluded", fmt::format("<b>{}</b>", a.fitted), "samples"),
      row("moving", std::to_string(a.moving), "samples"),
      row("at standstill (noise floor only, never fitted)", std::to_string(a.standstill), "samples"),
      row("outliers (impulsive; kept out of fits and floors)", std::to_string(a.outliers), "samples"),
      row("excluded (--direction, or unusable without a reference)", std::to_string(a.excluded), "samples"),
      row("without an angle", std::to_string(a.without_angle), "samples"),
      row("without the reference angle", std::to_string(a.without_reference), "samples"),
      row("time span", g3(a.span_s), "s"),
      row("travelled while moving, electrical", g3(a.revolutions_electrical), "rev"),
      row("travelled while moving, mechanical", g3(a.revolutions_mechanical), "rev"),
      row("reversals of direction", std::to_string(a.reversals), ""),
      row("standstills", std::to_string(a.standstills), ""),
  };
  return table("params", {"what", "count", "unit"}, rows) +
         fmt::format("<p class=\"small\">Residuals, harmonics, speed, time and direction breakdowns and the plots "
                     "cover the fitted samples; the noise floors use the standstill samples when the log has them. "
                     "Held-back validation: {}. Units: {}.</p>\n",
                     escape(a.fold_rule), escape(a.units));
}

std::string ratio_cell(const SignalResidual* s, double explained_ratio) {
  if (s == nullptr) return "<td class=\"na\">not fitted</td>";
  const double x = s->rms / s->floor;
  return fmt::format("<td class=\"{}\">{}<br><b>{}</b> floor (held back {})</td>", x <= explained_ratio ? "ok" : "bad",
                     escape(signal_value(s->signal, s->rms)), ratio(x), ratio(s->held_back_rms / s->floor));
}

const SignalResidual* find_signal(const ModelFit& f, std::string_view name) {
  for (const auto& s : f.signals) {
    if (s.signal == name) return &s;
  }
  return nullptr;
}

std::string steps_table(const DiscoveryRun& run, double explained_ratio) {
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    const Explanation& ex = run.steps[i];
    const ModelFit& f = ex.fit;
    std::string next;
    if (ex.verdict == Verdict::kMissingEffect && !ex.candidates.empty() && i + 1 < run.steps.size()) {
      const Candidate& c = ex.candidates.front();
      next = fmt::format("<b>+ {}</b> (BIC drop {:.0f}): {}", escape(c.effect), c.bic_drop, escape(c.reason));
    } else {
      next = escape(i + 1 == run.steps.size() ? run.stopped : "");
    }
    rows.push_back({std::to_string(i + 1),
                    fmt::format("<span class=\"swatch\" style=\"background:{}\"></span>{}", step_color(i, run.steps.size()),
                                escape(model_name(f))),
                    ratio_cell(find_signal(f, "position_error"), explained_ratio),
                    ratio_cell(find_signal(f, "sin_cos"), explained_ratio),
                    ratio_cell(find_signal(f, "i_dq"), explained_ratio), num_cell(std::to_string(f.parameters)),
                    num_cell(fmt::format("{:.1f}", f.bic)),
                    fmt::format("<td class=\"verdict-{0}\">{0}</td>", to_string(ex.verdict)),
                    "<td class=\"why\">" + next + "</td>"});
  }
  return table("steps",
               {"step", "model", "position-error residual", "sin/cos residual [1]", "i<sub>dq</sub> residual [A]", "k",
                "BIC", "verdict", "added next, and why"},
               rows);
}

std::string params_table(const ModelFit& f) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& p : f.params) {
    rows.push_back({"<code>" + escape(p.name) + "</code>", num_cell(fmt::format("{:.5g}", p.value)),
                    num_cell(fmt::format("{:.2g}", p.std_error)), escape(report::bare_unit(p.unit))});
  }
  if (rows.empty()) return "<p>The model has no fitted parameters (nuisance terms only).</p>\n";
  return table("params", {"parameter", "value", "standard error", "unit"}, rows) +
         fmt::format("<p class=\"small\">Standard errors, {}{}.</p>\n", escape(std_error_basis(f)),
                     f.robust_errors ? " (of the fit's scores: honest with correlated residuals)" : "");
}

std::string signals_table(const ModelFit& f, double explained_ratio) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& s : f.signals) {
    const double x = s.rms / s.floor;
    const double h = s.held_back_rms / s.floor;
    rows.push_back({escape(s.signal), escape(signal_unit(s.signal)), num_cell(escape(signal_value(s.signal, s.rms))),
                    num_cell(escape(signal_value(s.signal, s.raw_rms))), num_cell(escape(signal_value(s.signal, s.floor))),
                    fmt::format("<td class=\"num {}\">{}</td>", x <= explained_ratio ? "ok" : "bad", ratio(x)),
                    num_cell(escape(signal_value(s.signal, s.held_back_rms))),
                    fmt::format("<td class=\"num {}\">{}</td>",
                                !std::isfinite(h) ? "na" : h <= explained_ratio ? "ok" : "bad", ratio(h)),
                    num_cell(std::to_string(s.rows))});
  }
  return table("params",
               {"signal", "unit", "residual rms", "before (nuisance only)", "noise floor", "residual / floor",
                "held back rms", "held back / floor", "rows"},
               rows) +
         fmt::format("<p class=\"small\">Explained means every signal within {}x its floor, in-sample and held back "
                     "(fitted on one fold of the log, evaluated on the other).</p>\n",
                     g3(explained_ratio));
}

std::string floors_table(const FloorReport& floors) {
  std::vector<std::vector<std::string>> rows;
  auto row = [&](const char* signal, const FloorEstimate& e) {
    if (e.source.empty() || e.source == "none") return;
    rows.push_back({signal, escape(signal_unit(signal)), num_cell(escape(signal_value(signal, e.chosen))),
                    "<b>" + escape(e.source) + "</b>", num_cell(g3(e.second_difference)),
                    num_cell(fmt::format("{} ({} samples)", g3(e.standstill), e.standstill_samples)),
                    num_cell(g3(e.quantization))});
  };
  row("position_error", floors.rd);
  row("sin_cos", floors.sc);
  row("i_dq", floors.cur);
  return table("params",
               {"signal", "unit", "floor used", "from", "second differences", "standstill spread",
                "quantization part"},
               rows) +
         "<p class=\"small\">The noise floor is the residual a perfect model would leave. From standstill: the spread "
         "of each signal about its stretch's mean plus the quantization that motion adds (LSB²/12 per quantized "
         "channel); from second differences: per speed bin, the rms of the second differences of a saturated "
         "harmonic fit's residual / √6. The standstill estimate is used when the log has one.</p>\n";
}

std::string outliers_section(const ModelFit& f) {
  if (f.outliers.empty()) {
    return "<p>No outliers: no sample's second difference exceeds 12 robust standard deviations.</p>\n";
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& o : f.outliers) {
    std::vector<std::string> t;
    for (const double x : o.times) t.push_back(fmt::format("{:.4g}", x));
    rows.push_back({escape(o.signal), num_cell(std::to_string(o.count)), num_cell(g3(o.largest)), num_cell(g3(o.scale)),
                    escape(signal_unit(o.signal)), escape(fmt::format("{}", fmt::join(t, ", ")))});
  }
  return table("params",
               {"signal", "samples", "largest spike", "robust σ of second differences", "unit", "first at [s]"}, rows) +
         fmt::format("<p class=\"small\">Kept out of the fit and the floors. The position-error residual with them "
                     "included: {} ({} the floor).</p>\n",
                     escape(signal_value("position_error", f.rms_with_outliers_rad)),
                     ratio(f.rms_with_outliers_rad / f.noise_floor_rad));
}

std::string whiteness_and_directions(const ModelFit& f) {
  std::string o;
  const Whiteness& w = f.whiteness;
  if (w.lags > 0) {
    o += fmt::format("<p><b>Whiteness</b> of the position-error residual (autocorrelation at lags 1..{} against the 99 % "
                     "band ±{} of white noise over {} samples): {} lag{} outside, largest |ρ| = {}. {}</p>\n",
                     w.lags, g3(w.band), w.samples, w.outside, w.outside == 1 ? "" : "s", g3(w.max_abs),
                     w.outside == 0 ? "The residual looks like white noise."
                                    : "Correlated residual: structure left, or noise that is not white (a filter, "
                                      "the R/D loop); standard errors account for it when they come from the spread.");
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& d : f.directions) {
    rows.push_back({d.direction > 0 ? "forward" : "backward", num_cell(std::to_string(d.samples)),
                    num_cell(escape(signal_value("position_error", d.rms))), num_cell(ratio(d.rms / f.noise_floor_rad)),
                    num_cell(escape(signal_value("position_error", d.mean)))});
  }
  if (const std::string n = report::one_direction_note(f); !n.empty()) {
    o += "<p class=\"single\">" + escape(n) + fmt::format(" Its residual: rms {}, mean {}.</p>\n",
                                                            escape(signal_value("position_error", f.directions.front().rms)),
                                                            escape(signal_value("position_error", f.directions.front().mean)));
  } else if (!rows.empty()) {
    o += table("params", {"direction", "samples", "residual rms", "/ floor", "residual mean"}, rows) +
         "<p class=\"small\">An offset that flips sign with the direction is backlash or a delay.</p>\n";
  }
  return o;
}

std::string candidates_table(const Explanation& ex, bool currents) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& c : ex.candidates) {
    std::vector<std::string> values;
    for (const auto& p : c.params) {
      values.push_back(fmt::format("{} = {:.4g} ± {:.2g} {}", p.name, p.value, p.std_error, report::bare_unit(p.unit)));
    }
    const std::string in_place = c.replaces.empty() ? std::string() : " in place of <code>" + escape(c.replaces) + "</code>";
    std::vector<std::string> r = {"<code>" + escape(c.effect) + "</code>" + in_place,
                                  num_cell(escape(signal_value("position_error", c.residual_after_rad)))};
    if (currents) r.push_back(num_cell(g3(c.dq_residual_after)));
    r.insert(r.end(), {num_cell(fmt::format("{:.1f}", c.bic_drop)), num_cell(fmt::format("{:.3f}", c.err)),
                       c.proposed ? "yes" : "no", c.reaches_floor ? "yes" : "no",
                       escape(fmt::format("{}", fmt::join(c.fits_as_well, ", "))),
                       "<td class=\"why\">" + escape(c.reason) + "<br><span class=\"small\">" +
                           escape(fmt::format("{}", fmt::join(values, "; "))) + "</span></td>"});
    rows.push_back(std::move(r));
  }
  std::vector<std::string> header = {"effect", "position-error residual with it"};
  if (currents) header.emplace_back("i<sub>dq</sub> residual with it [A]");
  header.insert(header.end(), {"BIC drop", "ERR [share of the residual]", "proposed", "reaches the floor",
                               "fits as well here", "why, and its fitted values"});
  // Open while something is missing; folded once the model explains the log (nothing is proposed then).
  std::string o = std::string(ex.verdict == Verdict::kExplained ? "<details>" : "<details open>") +
                  "<summary>candidates ranked at the last step (lowest BIC first)</summary>\n" +
                  (rows.empty() ? std::string("<p>None ranked.</p>") : table("params", header, rows));
  for (const auto& n : ex.not_evaluated) o += "<p class=\"small\">not evaluated: " + escape(n) + "</p>";
  if (!ex.missing_pair.empty()) {
    o += "<p>Two effects are missing: " + escape(fmt::format("{}", fmt::join(ex.missing_pair, " and "))) +
         " reach the floor only together.</p>";
  }
  return o + "</details>\n";
}

}  // namespace

std::string format_model_html(const DiscoveryRun& run, const LogSamples& log, std::string_view log_path,
                              double explained_ratio, const std::string& pooled_section) {
  const Explanation& first = run.steps.front();
  const Explanation& last = run.steps.back();
  const ModelFit& f = last.fit;
  const std::string name = std::string(log_path.substr(log_path.find_last_of('/') + 1));
  std::vector<std::string> signals;
  for (const auto& s : f.signals) signals.push_back(s.signal);

  std::string o = html::page_head("resolver-model report: " + name);
  o += fmt::format("<h1>Resolver model discovery report: {}</h1>\n", escape(name));
  o += fmt::format(
      "<p class=\"meta\">log <code>{}</code> · {} samples from {} frames · p<sub>r</sub> = {}, p = {}{} · "
      "position error against {} · signals fitted: {}</p>\n",
      // The prepared log's count (a pooled run's LogSamples has no samples of its own).
      escape(log_path), run.log ? run.log->samples_in : static_cast<std::int64_t>(log.input.samples.size()), log.frames,
      run.log ? run.log->p_r : log.input.p_r, run.log ? run.log->p : log.input.p,
      log.bench_info ? " (BENCH_INFO)" : " (assumed)",
      f.reference ? "the reference encoder" : "the speed-smoothed ideal angle",
      escape(fmt::format("{}", fmt::join(signals, ", "))));
  o += fmt::format("<div class=\"verdict v-{}\"><b>{}</b><br><span class=\"small\">final step: {}</span></div>\n",
                   to_string(last.verdict), escape(verdict_words(run, explained_ratio)), escape(last.summary));
  o += "<nav class=\"small\">Contents: <a href=\"#coverage\">what the statistics cover</a> · <a href=\"#steps\">steps</a> · "
       "<a href=\"#final\">final model</a> · <a href=\"#plots\">plots</a> · <a href=\"#floors\">floors</a> · "
       "<a href=\"#candidates\">candidates</a> · <a href=\"#notes\">notes</a></nav>\n";

  o += "<h2 id=\"coverage\">What the statistics cover</h2>\n" + coverage_table(f);

  o += "<h2 id=\"steps\">Discovery, step by step</h2>\n";
  o += fmt::format(
      "<p class=\"small\">Each step fits the model, compares each signal's residual with its noise floor (explained: "
      "at most {}x, held back too), ranks the catalog effects not yet in the model by BIC, and adds the best one "
      "while the verdict is missing_effect. k: fitted parameters including nuisance terms. {}.</p>\n",
      g3(explained_ratio), escape(run.stopped));
  o += steps_table(run, explained_ratio);
  if (!first.where_it_fails.empty()) {
    o += fmt::format("<p><b>Where the {} fails</b></p>", run.steps.size() > 1 ? "starting model" : "model") +
         list(first.where_it_fails);
  }
  if (run.steps.size() > 1 && !last.where_it_fails.empty()) {
    o += "<p><b>Where the final model fails</b></p>" + list(last.where_it_fails);
  }

  if (!last.suggested_custom.empty()) {
    o += "<h2 id=\"custom\">Suggested custom effect</h2>\n<p>No catalog effect explains the residual. This "
         "<code>[[model.custom]]</code> block describes it; paste it into the resolverd config and add its name to "
         "<code>[model] effects</code>:</p>\n<pre class=\"custom\">" +
         escape(last.suggested_custom) + "</pre>\n";
  }
  o += fmt::format("<h2 id=\"final\">Final model: {}</h2>\n", escape(model_name(f)));
  o += params_table(f) + signals_table(f, explained_ratio);

  const std::vector<report::Plot> plots = report::report_plots(run);
  o += "<h2 id=\"plots\">Plots</h2>\n"
       "<p class=\"small\">Drag across a plot to zoom into that range, turn the mouse wheel to zoom about the "
       "pointer, shift-drag to pan, double-click (or <i>reset zoom</i>) to see it all; plots of the same angle zoom "
       "together. Click a legend entry to show or hide it (the individual samples start hidden). <i>download CSV</i> "
       "saves the plot's data: one row per point, with its series, in the units of the axes.</p>\n"
       "<noscript><p class=\"bad\">The plots are drawn by the page's script: enable JavaScript to see them. The "
       "tables do not need it.</p></noscript>\n";
  if (const std::string n = report::one_speed_note(f); !n.empty()) o += "<p class=\"single\">" + escape(n) + "</p>\n";
  o += html::figures(plots);

  o += "<h2 id=\"floors\">Noise floors, outliers, whiteness, directions</h2>\n" + floors_table(f.floors) +
       outliers_section(f) + whiteness_and_directions(f);
  o += "<h2 id=\"candidates\">Candidates</h2>\n" + candidates_table(last, f.currents_used);

  o += pooled_section;
  std::vector<std::string> notes = log.notes;
  if (log.bad_lines > 0) notes.push_back(fmt::format("{} malformed log lines skipped", log.bad_lines));
  if (log.problems > 0) notes.push_back(fmt::format("{} input problems counted (by reason above: a gap is counted, not skipped)", log.problems));
  for (const auto& ex : run.steps) {
    for (const auto& n : ex.fit.notes) {
      if (std::find(notes.begin(), notes.end(), n) == notes.end()) notes.push_back(n);
    }
  }
  for (const auto& n : last.not_evaluated) {
    if (n.find(": needs ") != std::string::npos) notes.push_back("not evaluated: " + n);
  }
  if (f.series.i_d_ref.empty()) notes.emplace_back("no dq-current plots: they need phase currents and the reference angle");
  if (notes.empty()) {
    notes.emplace_back("none: the log has the R/D angle, sin/cos envelopes, the reference angle and phase currents");
  }
  o += "<h2 id=\"notes\">Notes: what the log lacks, assumptions</h2>\n" + list(notes);
  o += fmt::format(
      "<p class=\"small\">BIC = n ln(RSS<sub>w</sub>/n) + k ln n over all weighted rows; ERR: the share of the model's "
      "weighted residual a candidate removes. Written by <code>resolver-model report</code>. Plots drawn with uPlot "
      "{} (MIT licence, embedded in this page with its notice).</p>\n",
      escape(report_assets::uplot_version()));
  return o + html::page_tail(plots);
}

void write_text_file(const std::string& path, std::string_view text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw std::system_error(errno, std::generic_category(), "cannot write " + path);
  const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int write_errno = errno;
  if (std::fclose(f) != 0 || !wrote) {
    throw std::system_error(wrote ? errno : write_errno, std::generic_category(), "cannot write " + path);
  }
}

}  // namespace resolver
