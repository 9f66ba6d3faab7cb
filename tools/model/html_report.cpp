#include "tools/model/html_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "daemon/core/angles.h"
#include "tools/model/svg_plot.h"

namespace resolver {

namespace {

using svg::escape;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / kPi;
constexpr int kAngleBins = 36;  // 10 deg bins for the dq means: ~55 samples each at 2000 series points

std::string g3(double v) { return fmt::format("{:.3g}", v); }

std::string join(const std::vector<std::string>& v, std::string_view sep) {
  std::string o;
  for (const auto& s : v) o += (o.empty() ? "" : std::string(sep)) + s;
  return o;
}

std::string model_name(const ModelFit& f) { return f.effects.empty() ? "(nuisance only)" : join(f.effects, " + "); }

const SignalResidual* find_signal(const ModelFit& f, std::string_view name) {
  for (const auto& s : f.signals) {
    if (s.signal == name) return &s;
  }
  return nullptr;
}

/// Effects of `later` that `earlier` lacks, in order.
std::vector<std::string> added_effects(const ModelFit& earlier, const ModelFit& later) {
  std::vector<std::string> out;
  for (const auto& e : later.effects) {
    if (std::find(earlier.effects.begin(), earlier.effects.end(), e) == earlier.effects.end()) out.push_back(e);
  }
  return out;
}

/// Start red, end blue, in between distinct hues: the spectrum and speed plots read left to right as "before -> after".
std::string step_color(std::size_t i, std::size_t n) {
  static constexpr const char* kMiddle[] = {"#e67e22", "#8e44ad", "#16a085", "#b7950b", "#7f8c8d"};
  if (i + 1 == n) return "#1f5fa8";
  if (i == 0) return "#c0392b";
  return kMiddle[(i - 1) % std::size(kMiddle)];
}

std::string step_label(const DiscoveryRun& run, std::size_t i) {
  if (i == 0) return fmt::format("step 1: {}", model_name(run.steps[0].fit));
  return fmt::format("step {}: + {}", i + 1, join(added_effects(run.steps[i - 1].fit, run.steps[i].fit), " + "));
}

// ---- words -------------------------------------------------------------------------------

std::string verdict_words(const DiscoveryRun& run, double ratio) {
  const Explanation& first = run.steps.front();
  const Explanation& last = run.steps.back();
  const auto added = added_effects(first.fit, last.fit);
  const std::string added_text =
      added.empty() ? std::string()
                    : fmt::format(" after adding {} to {}", join(added, " and "), model_name(first.fit));
  switch (last.verdict) {
    case Verdict::kExplained:
      return fmt::format(
          "Explained: the model {} accounts for every signal in this log to within {}x its noise floor{}.",
          model_name(last.fit), g3(ratio), added.empty() ? "; the starting model needed nothing more" : added_text);
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

std::string ratio_cell(const SignalResidual* s, double ratio, std::string_view unit) {
  if (s == nullptr) return "<td class=\"na\">not fitted</td>";
  const double x = s->rms / s->floor;
  return fmt::format("<td class=\"{}\" title=\"residual {} {}, floor {} {}\"><b>{:.2f}x</b> floor</td>",
                     x <= ratio ? "ok" : "bad", g3(s->rms), unit, g3(s->floor), unit, x);
}

std::string steps_table(const DiscoveryRun& run, double ratio) {
  std::string o =
      "<table class=\"steps\"><tr><th>step</th><th>model</th><th>position-error residual</th><th>sin/cos</th>"
      "<th>i<sub>dq</sub></th><th>k</th><th>BIC</th><th>verdict</th><th>added next, and why</th></tr>\n";
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    const Explanation& ex = run.steps[i];
    const ModelFit& f = ex.fit;
    const double x = f.residual_rms_rad / f.noise_floor_rad;
    std::string next;
    if (ex.verdict == Verdict::kMissingEffect && !ex.candidates.empty() && i + 1 < run.steps.size()) {
      const Candidate& c = ex.candidates.front();
      next = fmt::format("<b>+ {}</b> (BIC drop {:.0f}): {}", escape(c.effect), c.bic_drop, escape(c.reason));
    } else {
      next = escape(i + 1 == run.steps.size() ? run.stopped : "");
    }
    o += fmt::format(
        "<tr><td>{}</td><td><span class=\"swatch\" style=\"background:{}\"></span>{}</td>"
        "<td class=\"{}\">{} rad = {} arcmin<br><b>{:.2f}x</b> floor ({} rad)</td>{}{}<td>{}</td><td>{:.1f}</td>"
        "<td class=\"verdict-{}\">{}</td><td class=\"why\">{}</td></tr>\n",
        i + 1, step_color(i, run.steps.size()), escape(model_name(f)), x <= ratio ? "ok" : "bad",
        g3(f.residual_rms_rad), g3(rad_to_arcmin(f.residual_rms_rad)), x, g3(f.noise_floor_rad),
        ratio_cell(find_signal(f, "sin_cos"), ratio, "of the amplitude"),
        ratio_cell(find_signal(f, "i_dq"), ratio, "A"), f.parameters, f.bic, to_string(ex.verdict),
        to_string(ex.verdict), next);
  }
  return o + "</table>\n";
}

std::string params_table(const ModelFit& f) {
  std::string o = "<table class=\"params\"><tr><th>parameter</th><th>value</th><th>standard error</th></tr>\n";
  for (const auto& p : f.params) {
    o += fmt::format("<tr><td><code>{}</code></td><td class=\"num\">{:.5g}</td><td class=\"num\">{:.2g}</td></tr>\n",
                     escape(p.name), p.value, p.std_error);
  }
  return o + "</table>\n";
}

std::string candidates_table(const Explanation& ex) {
  std::string o =
      "<details><summary>candidates ranked at the last step (lowest BIC first)</summary>\n"
      "<table class=\"params\"><tr><th>effect</th><th>residual after [rad]</th><th>BIC drop</th>"
      "<th>proposed</th><th>why</th></tr>\n";
  for (const auto& c : ex.candidates) {
    o += fmt::format(
        "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{:.1f}</td><td>{}</td><td "
        "class=\"why\">{}</td></tr>\n",
        escape(c.effect), g3(c.residual_after_rad), c.bic_drop, c.proposed ? "yes" : "no", escape(c.reason));
  }
  o += "</table>";
  for (const auto& n : ex.not_evaluated) o += "<p class=\"small\">not evaluated: " + escape(n) + "</p>";
  return o + "</details>\n";
}

std::string list(const std::vector<std::string>& items) {
  std::string o = "<ul>";
  for (const auto& s : items) o += "<li>" + escape(s) + "</li>";
  return o + "</ul>\n";
}

// ---- figures -----------------------------------------------------------------------------

std::vector<double> scaled(const std::vector<double>& v, double k) {
  std::vector<double> o(v.size());
  std::transform(v.begin(), v.end(), o.begin(), [k](double a) { return a * k; });
  return o;
}

/// Means of y in equal bins of x over [0, 360): the ripple through the angle, with the noise averaged down.
std::pair<std::vector<double>, std::vector<double>> binned_mean(const std::vector<double>& x_deg,
                                                                const std::vector<double>& y) {
  std::vector<double> sum(kAngleBins, 0.0), cnt(kAngleBins, 0.0), xc(kAngleBins), ym(kAngleBins, kNaN);
  for (std::size_t i = 0; i < x_deg.size() && i < y.size(); ++i) {
    const int b = std::clamp(static_cast<int>(x_deg[i] / 360.0 * kAngleBins), 0, kAngleBins - 1);
    sum[b] += y[i];
    cnt[b] += 1.0;
  }
  for (int b = 0; b < kAngleBins; ++b) {
    xc[b] = (b + 0.5) * 360.0 / kAngleBins;
    if (cnt[b] > 0.0) ym[b] = sum[b] / cnt[b];
  }
  return {xc, ym};
}

svg::Axis axis(std::string label) {
  svg::Axis a;
  a.label = std::move(label);
  return a;
}

svg::Plot make_plot(std::string id, std::string title, svg::Axis x, svg::Axis y) {
  svg::Plot p;
  p.id = std::move(id);
  p.title = std::move(title);
  p.x = std::move(x);
  p.y = std::move(y);
  return p;
}

svg::Series make_series(std::string label, std::string color, std::vector<double> x, std::vector<double> y,
                        svg::Mark mark = svg::Mark::kLine, double size = 1.5, double opacity = 1.0) {
  svg::Series s;
  s.label = std::move(label);
  s.color = std::move(color);
  s.x = std::move(x);
  s.y = std::move(y);
  s.mark = mark;
  s.size = size;
  s.opacity = opacity;
  return s;
}

svg::HLine floor_line(double y, std::string label, std::string color) {
  svg::HLine h;
  h.y = y;
  h.label = std::move(label);
  h.color = std::move(color);
  return h;
}

/// θ as the library's series has it: the reference encoder's, else the speed-smoothed ideal angle.
svg::Axis angle_axis(bool reference) {
  svg::Axis a = axis(reference ? "θ, resolver electrical angle from the reference encoder [deg]"
                               : "θ, resolver electrical angle, speed-smoothed ideal [deg]");
  a.lo = 0.0;
  a.hi = 360.0;
  a.tick_step = 45.0;
  return a;
}

std::string figure(std::string_view id, std::string_view caption, const std::string& body) {
  return fmt::format("<figure id=\"{}\">{}<figcaption>{}</figcaption></figure>\n", id, body, caption);
}

/// Log-scale spectra: the range ends this far below the floor, so a harmonic the fit
/// removed to 1e-10 does not squeeze the ones that matter into the top of the plot.
constexpr double kSpectrumRangeBelowFloor = 1e-3;

/// [deg] Model lines connect samples at most this far apart in θ. At 2000 series points
/// a constant-speed log has ~10 deg between samples; at high speed the decimation skips
/// round the revolution, the lines break up, and the model's dots carry the curve.
constexpr double kMaxLineStepDeg = 30.0;

std::string fig_position_error(const DiscoveryRun& run) {
  const ModelFit& first = run.steps.front().fit;
  const ModelFit& last = run.steps.back().fit;
  const ResidualSeries& s = last.series;
  const std::size_t n = run.steps.size();
  const auto theta = scaled(s.theta, kRadToDeg);
  const double am = rad_to_arcmin(1.0);

  svg::Plot a = make_plot("pe", "Position error ε = θ_true − θ_rd vs angle: measured and model",
                          angle_axis(last.reference), axis("ε [arcmin]"));
  a.height = 300;
  if (n > 1) {
    svg::Series m =
        make_series("model, step 1: " + model_name(first), step_color(0, n), scaled(first.series.theta, kRadToDeg),
                    scaled(first.series.eps_model, am), svg::Mark::kLine, 2.0);
    m.dashed = true;
    m.max_x_step = kMaxLineStepDeg;
    a.series.push_back(m);
  }
  svg::Series m = make_series(fmt::format("model, step {}: {}", n, model_name(last)), step_color(n - 1, n), theta,
                              scaled(s.eps_model, am), svg::Mark::kLine, 2.5);
  m.max_x_step = kMaxLineStepDeg;
  a.series.push_back(m);
  a.series.push_back(make_series("", m.color, m.x, m.y, svg::Mark::kDots, 3.0));  // where the line breaks up
  // Measured on top of the models: where they agree the dots sit on the line.
  a.series.push_back(make_series("measured", "#222", theta, scaled(s.eps_measured, am), svg::Mark::kDots, 3.0, 0.55));

  svg::Plot b = make_plot("pr", fmt::format("Residual ε − model of step {} vs angle", n), angle_axis(last.reference),
                          axis("residual [arcmin]"));
  b.height = 260;
  std::vector<double> residual(s.eps_measured.size());
  for (std::size_t i = 0; i < residual.size(); ++i) residual[i] = (s.eps_measured[i] - s.eps_model[i]) * am;
  b.series.push_back(make_series(fmt::format("residual, step {}: {}", n, model_name(last)), step_color(n - 1, n), theta,
                                 residual, svg::Mark::kDots, 4.0, 0.7));
  const double fl = rad_to_arcmin(last.noise_floor_rad);
  b.hlines.push_back(floor_line(fl, fmt::format("± noise floor (rms) {} arcmin", g3(fl)), "#222"));
  b.hlines.push_back(floor_line(-fl, "", "#222"));
  return figure(
      "fig-position",
      fmt::format(
          "Position error against {}, {} samples (evenly decimated). The lines are the fitted ε̂(θ); the residual "
          "is what the final model leaves, to be compared with the noise floor{}.",
          last.reference ? "the reference encoder" : "the speed-smoothed ideal angle", s.theta.size(),
          n > 1 ? " (the starting model's residual is the gap between the dots and the dashed line)" : ""),
      svg::render(a) + svg::render(b));
}

std::string fig_spectrum(const DiscoveryRun& run) {
  svg::Plot p = make_plot("spec", "Position-error residual by harmonic of θ, before and after each added effect",
                          axis("harmonic order of θ, resolver electrical [cycles per revolution of θ]"),
                          axis("residual amplitude [arcmin]"));
  p.y.log = true;
  p.height = 300;
  for (const auto& h : run.steps.front().fit.harmonics) {
    p.x.categories.push_back(h.order == 0 ? std::string("0 (constant)") : fmt::format("{}θ", h.order));
  }
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    std::vector<double> v;
    for (const auto& h : run.steps[i].fit.harmonics) v.push_back(rad_to_arcmin(h.amplitude));
    p.bars.push_back({step_label(run, i), step_color(i, run.steps.size()), v});
  }
  const double fl = rad_to_arcmin(run.steps.back().fit.noise_floor_rad);
  p.y.lo = fl * kSpectrumRangeBelowFloor;
  p.hlines.push_back(floor_line(fl, fmt::format("noise floor (rms per sample) {} arcmin", g3(fl)), "#222"));
  p.hlines.push_back(floor_line(fl / 5.0, "a fifth of the floor: harmonics named in 'where it fails'", "#999"));
  return figure(
      "fig-spectrum",
      "Amplitude of each harmonic of the position-error residual, one bar per discovery step (log scale; hover a bar "
      "for its value). A missing effect shows as bars far above the floor that drop in the step that adds it.",
      svg::render(p));
}

std::string fig_dq_spectrum(const DiscoveryRun& run) {
  const ModelFit& last = run.steps.back().fit;
  const SignalResidual* dq = find_signal(last, "i_dq");
  if (dq == nullptr || last.harmonics_id.empty()) return {};
  svg::Plot p = make_plot("dqspec", "i_d, i_q residual by harmonic of θ_e, per step",
                          axis("harmonic order of θ_e [cycles per motor electrical revolution]"),
                          axis("amplitude √(A_d² + A_q²) [mA]"));
  p.y.log = true;
  p.height = 260;
  for (const auto& h : last.harmonics_id)
    p.x.categories.push_back(h.order == 0 ? std::string("0 (constant)") : fmt::format("{}θ_e", h.order));
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    const ModelFit& f = run.steps[i].fit;
    std::vector<double> v;
    for (std::size_t k = 0; k < f.harmonics_id.size() && k < f.harmonics_iq.size(); ++k) {
      v.push_back(1e3 * std::hypot(f.harmonics_id[k].amplitude, f.harmonics_iq[k].amplitude));
    }
    p.bars.push_back({step_label(run, i), step_color(i, run.steps.size()), v});
  }
  p.y.lo = 1e3 * dq->floor * kSpectrumRangeBelowFloor;
  p.hlines.push_back(floor_line(1e3 * dq->floor, fmt::format("noise floor {} mA", g3(1e3 * dq->floor)), "#222"));
  return figure(
      "fig-dq-spectrum",
      "The dq-current residual by harmonic of the motor electrical angle: current-sensor offsets show at 1θ_e, gain "
      "mismatch at 2θ_e, dead time at 6θ_e.",
      svg::render(p));
}

std::string fig_speed(const DiscoveryRun& run, int width) {
  svg::Plot p = make_plot("speed", "Position-error residual vs speed, per step", axis("speed, mechanical [r/min]"),
                          axis("residual rms [arcmin]"));
  p.y.log = true;
  p.width = width;
  p.height = 280;
  std::size_t bins = 0;
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    svg::Series s = make_series(step_label(run, i), step_color(i, run.steps.size()), {}, {}, svg::Mark::kLineDots, 2.0);
    for (const auto& b : run.steps[i].fit.speed_bins) {
      s.x.push_back(b.rpm_mid);
      s.y.push_back(rad_to_arcmin(b.rms));
    }
    bins = std::max(bins, s.x.size());
    p.series.push_back(std::move(s));
  }
  const double fl = rad_to_arcmin(run.steps.back().fit.noise_floor_rad);
  p.hlines.push_back(floor_line(fl, fmt::format("noise floor {} arcmin", g3(fl)), "#222"));
  return figure(
      "fig-speed",
      fmt::format("Residual rms in {} speed bin{} (empty bins dropped). A residual that grows with speed points at "
                  "sampling skew or the R/D tracking loop.{}",
                  bins, bins == 1 ? "" : "s", bins <= 1 ? " This log runs at one speed: one point per step." : ""),
      svg::render(p));
}

std::string fig_time(const DiscoveryRun& run, int width) {
  svg::Plot p = make_plot("time", "Position-error residual vs time, per step",
                          axis("time from the log's first sample [s]"), axis("residual rms [arcmin]"));
  p.y.log = true;
  p.width = width;
  p.height = 280;
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    svg::Series s = make_series(step_label(run, i), step_color(i, run.steps.size()), {}, {}, svg::Mark::kLineDots, 2.0);
    for (const auto& b : run.steps[i].fit.time_bins) {
      s.x.push_back(0.5 * (b.t_lo + b.t_hi));
      s.y.push_back(rad_to_arcmin(b.rms));
    }
    p.series.push_back(std::move(s));
  }
  if (!run.steps.back().fit.time_bins.empty()) {  // the whole log, so the windows' centres sit inside
    p.x.lo = 0.0;
    p.x.hi = run.steps.back().fit.time_bins.back().t_hi;
  }
  const double fl = rad_to_arcmin(run.steps.back().fit.noise_floor_rad);
  p.hlines.push_back(floor_line(fl, fmt::format("noise floor {} arcmin", g3(fl)), "#222"));
  return figure(
      "fig-time",
      fmt::format("Residual rms in {} equal windows of the log. No catalog effect changes with time: a residual that "
                  "grows or shrinks from window to window at the same speed is a drift outside the catalog "
                  "(e.g. with temperature).",
                  run.steps.back().fit.time_bins.size()),
      svg::render(p));
}

std::string fig_dq(const DiscoveryRun& run, int width) {
  const ModelFit& last = run.steps.back().fit;
  const ResidualSeries& s = last.series;
  if (s.i_d_raw.empty()) return {};
  const auto theta = scaled(s.theta, kRadToDeg);
  const auto panel = [&](std::string_view id, std::string_view name, const std::vector<double>& raw,
                         const std::vector<double>& comp, const std::vector<double>& ref) {
    svg::Plot p = make_plot(std::string(id), fmt::format("{}: raw, compensated and reference angle", name),
                            angle_axis(last.reference), axis(fmt::format("{}, mean per 10° of θ [A]", name)));
    p.width = width;
    p.height = 280;
    p.x.tick_step = 90.0;
    auto [x1, y1] = binned_mean(theta, raw);
    auto [x2, y2] = binned_mean(theta, comp);
    auto [x3, y3] = binned_mean(theta, ref);
    p.series.push_back(make_series("raw R/D angle", "#c0392b", x1, y1, svg::Mark::kLine, 2.0));
    p.series.push_back(make_series("compensated (final model)", "#1f5fa8", x2, y2, svg::Mark::kLine, 2.0));
    svg::Series r = make_series("reference encoder", "#222", x3, y3, svg::Mark::kLine, 1.5);
    r.dashed = true;
    p.series.push_back(r);
    return svg::render(p);
  };
  return figure(
      "fig-dq",
      "dq currents (Park transform at θ_e) with three angles: the raw R/D angle, the R/D angle corrected by the final "
      "model's ε̂, and the reference encoder; means over 10° bins of θ, so the per-sample noise averages down. An angle "
      "error ε puts a ripple of about i_q·ε on i_d; compensation brings the blue line onto the dashed reference.",
      "<div class=\"row\">" + panel("dqd", "i_d", s.i_d_raw, s.i_d_comp, s.i_d_ref) +
          panel("dqq", "i_q", s.i_q_raw, s.i_q_comp, s.i_q_ref) + "</div>");
}

constexpr std::string_view kCss = R"(
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;color:#1d1d1f;margin:24px auto;max-width:1108px;padding:0 16px}
h1{font-size:24px;margin:0 0 4px}h2{font-size:18px;margin:28px 0 8px;border-bottom:1px solid #ddd;padding-bottom:4px}
.meta{color:#555;margin:0 0 12px}code{font:13px ui-monospace,"DejaVu Sans Mono",monospace}
.verdict{padding:10px 14px;border-radius:6px;border-left:6px solid;margin:12px 0}
.v-explained{background:#eaf6ec;border-color:#2e8b57}.v-missing_effect{background:#fff4e0;border-color:#e67e22}.v-unexplained{background:#fdecea;border-color:#c0392b}
table{border-collapse:collapse;margin:8px 0;width:100%}th,td{border:1px solid #ddd;padding:4px 6px;vertical-align:top;text-align:left}
th{background:#f4f4f6}td.num{text-align:right;font-variant-numeric:tabular-nums}td.ok{background:#eaf6ec}td.bad{background:#fdecea}td.na{color:#999}
td.why{font-size:12px;max-width:420px}.verdict-explained{color:#2e8b57;font-weight:600}.verdict-missing_effect{color:#c66a00;font-weight:600}
.verdict-unexplained{color:#c0392b;font-weight:600}.swatch{display:inline-block;width:10px;height:10px;margin-right:6px;border-radius:2px}
table.params{width:auto}.small{font-size:12px;color:#555;margin:2px 0}
figure{margin:16px 0}.row{display:flex;gap:20px}.row figure{margin:16px 0;flex:1}figcaption{font-size:12px;color:#555;max-width:1000px}
svg.plot{display:block;font:12px system-ui,"DejaVu Sans",sans-serif}svg .title{font-weight:600;font-size:13px}
svg .tick{fill:#444;font-size:11px}svg .axis{fill:#222}svg .grid{stroke:#e4e4e4}svg .grid.minor{stroke:#f2f2f2}
svg .frame{fill:none;stroke:#999}
)";

}  // namespace

DiscoveryRun run_discovery(const DiscoveryInput& input, std::vector<std::string> effects,
                           const DiscoveryOptions& options, int max_steps, const std::function<void(int)>& on_step) {
  DiscoveryRun run;
  max_steps = std::max(1, max_steps);
  const PreparedLog log = prepare_log(input, options.prepare);  // once: every step fits the same rows
  for (int step = 0; step < max_steps; ++step) {
    if (on_step) on_step(step + 1);
    try {
      run.steps.push_back(explain_prepared(log, effects, options));
    } catch (const std::exception& e) {
      if (run.steps.empty()) throw;
      run.stopped = fmt::format("adding {} failed: {}", effects.back(), e.what());
      return run;
    }
    const Explanation& ex = run.steps.back();
    if (ex.verdict != Verdict::kMissingEffect || ex.candidates.empty()) {
      run.stopped = ex.verdict == Verdict::kExplained ? "done: every signal is at the noise floor"
                                                      : "done: no catalog effect explains the rest of the residual";
      return run;
    }
    effects.push_back(ex.candidates.front().effect);
  }
  run.stopped = fmt::format("stopped at the limit of {} step{}; {} is proposed next", max_steps,
                            max_steps == 1 ? "" : "s", effects.back());
  return run;
}

std::string summarize_discovery(const DiscoveryRun& run) {
  const ModelFit& f = run.steps.back().fit;
  return fmt::format("{} after {} step{}: {}, position-error residual {} rad = {} arcmin ({:.2f}x floor)",
                     to_string(run.steps.back().verdict), run.steps.size(), run.steps.size() == 1 ? "" : "s",
                     model_name(f), g3(f.residual_rms_rad), g3(rad_to_arcmin(f.residual_rms_rad)),
                     f.residual_rms_rad / f.noise_floor_rad);
}

std::string format_model_html(const DiscoveryRun& run, const LogSamples& log, std::string_view log_path,
                              double explained_ratio) {
  const Explanation& first = run.steps.front();
  const Explanation& last = run.steps.back();
  const std::string name = std::string(log_path.substr(log_path.find_last_of('/') + 1));
  std::vector<std::string> signals;
  for (const auto& s : last.fit.signals) signals.push_back(s.signal);

  std::string o =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta name=\"viewport\" "
      "content=\"width=device-width\">\n";
  o += fmt::format("<title>resolver-model report: {}</title>\n<style>{}</style></head><body>\n", escape(name), kCss);
  o += fmt::format("<h1>Resolver model discovery report: {}</h1>\n", escape(name));
  o += fmt::format(
      "<p class=\"meta\">log <code>{}</code> · {} samples from {} frames · p<sub>r</sub> = {}, p = {}{} · "
      "position error against {} · signals fitted: {}</p>\n",
      escape(log_path), log.input.samples.size(), log.frames, log.input.p_r, log.input.p,
      log.bench_info ? " (BENCH_INFO)" : " (assumed)",
      last.fit.reference ? "the reference encoder" : "the speed-smoothed ideal angle", escape(join(signals, ", ")));
  o += fmt::format("<div class=\"verdict v-{}\"><b>{}</b><br><span class=\"small\">final step: {}</span></div>\n",
                   to_string(last.verdict), escape(verdict_words(run, explained_ratio)), escape(last.summary));

  o += "<h2>Discovery, step by step</h2>\n";
  o += fmt::format(
      "<p class=\"small\">Each step fits the model, compares each signal's residual with its noise floor (explained: "
      "at most {}x), ranks the catalog effects not yet in the model by BIC, and adds the best one while the verdict is "
      "missing_effect. k: fitted parameters including nuisance terms. {}.</p>\n",
      g3(explained_ratio), escape(run.stopped));
  o += steps_table(run, explained_ratio);
  if (!first.where_it_fails.empty()) {
    o += fmt::format("<p><b>Where the {} fails</b></p>", run.steps.size() > 1 ? "starting model" : "model") +
         list(first.where_it_fails);
  }
  if (run.steps.size() > 1 && !last.where_it_fails.empty())
    o += "<p><b>Where the final model fails</b></p>" + list(last.where_it_fails);

  o += fmt::format("<h2>Final model: {}</h2>\n", escape(model_name(last.fit)));
  o += params_table(last.fit) + candidates_table(last);

  o += "<h2>Plots</h2>\n";
  // Two plots side by side in the 1108 px content width (body max-width minus padding).
  constexpr int kHalf = 544;
  o += fig_position_error(run) + fig_spectrum(run);
  o += "<div class=\"row\">" + fig_speed(run, kHalf) + fig_time(run, kHalf) + "</div>\n";
  o += fig_dq_spectrum(run);
  const std::string dq = fig_dq(run, kHalf);
  o += dq;

  std::vector<std::string> notes = log.notes;
  if (log.bad_lines > 0) notes.push_back(fmt::format("{} malformed log lines skipped", log.bad_lines));
  if (log.problems > 0) notes.push_back(fmt::format("{} decode problems (CRC, counters) skipped", log.problems));
  for (const auto& ex : run.steps) {
    for (const auto& n : ex.fit.notes) {
      if (std::find(notes.begin(), notes.end(), n) == notes.end()) notes.push_back(n);
    }
  }
  for (const auto& n : last.not_evaluated) {
    if (n.find(": needs ") != std::string::npos) notes.push_back("not evaluated: " + n);
  }
  if (dq.empty()) notes.emplace_back("no dq-current plot: it needs phase currents and the reference angle");
  if (notes.empty())
    notes.emplace_back("none: the log has the R/D angle, sin/cos envelopes, the reference angle and phase currents");
  o += "<h2>Notes: what the log lacks, assumptions</h2>\n" + list(notes);
  o +=
      "<p class=\"small\">Noise floor: rms of second differences of a saturated per-speed Fourier fit's residual / √6, "
      "estimated from the same data. BIC = n ln(RSS<sub>w</sub>/n) + k ln n over all weighted rows. Written by "
      "<code>resolver-model report</code>.</p>\n";
  return o + "</body></html>\n";
}

void write_text_file(const std::string& path, std::string_view text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int write_errno = errno;
  if (std::fclose(f) != 0 || !wrote) {
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(wrote ? errno : write_errno));
  }
}

}  // namespace resolver
