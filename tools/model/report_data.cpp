#include "tools/model/report_data.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "daemon/core/angles.h"
#include "tools/model/json_text.h"
#include "tools/model/row_prediction.h"

namespace resolver::report {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kArcminPerRad = rad_to_arcmin(1.0);
constexpr const char* kMeasuredColor = "#222222";
constexpr const char* kFloorColor = "#555555";
/// Log-scale spectra end this far below the floor, so a harmonic the fit removed to
/// 1e-10 does not squeeze the ones that matter into the top of the plot.
constexpr double kSpectrumRangeBelowFloor = 1e-3;
/// The harmonics named in "where it fails" are those above a fifth of the floor (narration.cpp).
constexpr double kNamedHarmonicShare = 0.2;

std::vector<double> scaled(const std::vector<double>& v, double k) {
  std::vector<double> o(v.size());
  std::transform(v.begin(), v.end(), o.begin(), [k](double a) { return a * k; });
  return o;
}

std::vector<double> degrees(const std::vector<double>& rad) {
  std::vector<double> o(rad.size());
  std::transform(rad.begin(), rad.end(), o.begin(), [](double a) { return rad_to_deg(wrap_2pi(a)); });
  return o;
}

std::vector<double> difference(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> o(std::min(a.size(), b.size()));
  for (std::size_t i = 0; i < o.size(); ++i) o[i] = a[i] - b[i];
  return o;
}

/// A value a log axis can draw (NaN otherwise: no point).
double positive(double v) { return v > 0.0 ? v : kNaN; }

Series line(std::string label, std::string color, std::vector<double> x, std::vector<double> y, double width = 2.0) {
  Series s;
  s.label = std::move(label);
  s.color = std::move(color);
  s.mark = Mark::kLine;
  s.x = std::move(x);
  s.y = std::move(y);
  s.width = width;
  return s;
}

/// The binned means as a line (the model: one curve through the angle).
Series mean_line(std::string label, std::string color, const AngleBins& b, double width = 2.5) {
  return line(std::move(label), std::move(color), b.centre, b.mean, width);
}

/// The binned means as dots in a +-1 sd band: measured data, drawn over the model.
Series band(std::string label, std::string color, const AngleBins& b) {
  Series s = line(std::move(label), std::move(color), b.centre, b.mean, 4.0);
  s.mark = Mark::kBand;
  s.spread = b.sd;
  s.count = b.count;
  return s;
}

/// Every sample as a dot, hidden until the reader shows it.
Series samples(std::string label, std::string color, std::vector<double> x_deg, std::vector<double> y) {
  Series s = line(std::move(label), std::move(color), std::move(x_deg), std::move(y), 2.0);
  s.mark = Mark::kPoints;
  s.hidden = true;
  s.digits = 5;
  return s;
}

/// A horizontal reference line (a noise floor) across [lo, hi] of x.
Series hline(std::string label, double lo, double hi, double y) {
  Series s = line(std::move(label), kFloorColor, {lo, hi}, {y, y}, 1.5);
  s.dashed = true;
  return s;
}

Axis axis(std::string label, std::string unit, std::string column) {
  Axis a;
  a.label = std::move(label);
  a.unit = std::move(unit);
  a.column = std::move(column);
  return a;
}

Axis angle_axis(bool reference) {
  Axis a = axis(reference ? "θ, resolver electrical angle (reference encoder)"
                          : "θ, resolver electrical angle (speed-smoothed ideal)",
                "deg", "theta_deg");
  a.lo = 0.0;
  a.hi = 360.0;
  a.step = 45.0;
  return a;
}

Axis theta_e_axis() {
  Axis a = axis("θ_e, motor electrical angle (reference encoder)", "deg", "theta_e_deg");
  a.lo = 0.0;
  a.hi = 360.0;
  a.step = 60.0;
  return a;
}

Axis order_axis(const std::string& of, std::string column, int lo, int hi) {
  Axis a = axis("harmonic order of " + of, "cycles/rev", std::move(column));
  a.lo = lo - 0.5;
  a.hi = hi + 0.5;
  a.step = 1.0;
  return a;
}

Plot plot(std::string id, std::string title, Axis x, Axis y) {
  Plot p;
  p.id = std::move(id);
  p.title = std::move(title);
  p.x = std::move(x);
  p.y = std::move(y);
  return p;
}

/// One pass over the log's fitted rows with one step's model: everything the angle plots bin.
struct StepBins {
  AngleBinner measured{kAngleBins, kArcminPerRad};  ///< position error by theta [arcmin]
  AngleBinner model{kAngleBins, kArcminPerRad};
  AngleBinner residual{kAngleBins, kArcminPerRad};
  AngleBinner d{}, q{}, d_model{}, q_model{};       ///< [A] by theta_e, reference frame
  AngleBinner d_raw{kAngleBins, 1e3}, d_comp{kAngleBins, 1e3};  ///< [mA] by theta: dq with the R/D angle minus with the reference
  AngleBinner q_raw{kAngleBins, 1e3}, q_comp{kAngleBins, 1e3};
  std::int64_t rows = 0;                             ///< fitted rows with a position error
};

StepBins bin_rows(const PreparedLog& log, const ModelFit& fit) {
  StepBins b;
  const double e_per_r = static_cast<double>(log.p) / log.p_r;
  // The drive's angle is the true one less the R/D error: Park at theta_e + delta rotates (d, q) by -delta.
  const auto rotated = [](double d, double q, double delta) {
    return std::pair{d * std::cos(delta) + q * std::sin(delta), q * std::cos(delta) - d * std::sin(delta)};
  };
  const RowPredictor predict(log, fit.model);
  for (const FitRow& r : log.rows) {
    if (!r.fitted()) continue;
    const SignalValues effects = predict.effects(r);
    SignalValues p = effects;
    p += predict.constants();
    const bool has_pos = log.rd ? r.has(FitRow::kHasRd) : r.has(FitRow::kHasSc);
    if (has_pos) {
      const double y = log.rd ? r.y_rd : r.y_sa;
      const double m = log.rd ? p.rd : p.sa;
      b.measured.add(r.sig.theta, y);
      b.model.add(r.sig.theta, m);
      b.residual.add(r.sig.theta, y - m);
      ++b.rows;
    }
    if (log.currents && r.has(FitRow::kHasCur)) {
      b.d.add(r.sig.theta_e, r.y_d);
      b.q.add(r.sig.theta_e, r.y_q);
      b.d_model.add(r.sig.theta_e, p.d);
      b.q_model.add(r.sig.theta_e, p.q);
      if (log.rd && r.has(FitRow::kHasRd)) {
        const auto [dr, qr] = rotated(r.y_d, r.y_q, -e_per_r * r.y_rd);
        // Compensation subtracts the model's effects (a fitted constant is the angle's zero, not an error).
        const auto [dc, qc] = rotated(r.y_d, r.y_q, -e_per_r * (r.y_rd - effects.rd));
        b.d_raw.add(r.sig.theta, dr - r.y_d);
        b.q_raw.add(r.sig.theta, qr - r.y_q);
        b.d_comp.add(r.sig.theta, dc - r.y_d);
        b.q_comp.add(r.sig.theta, qc - r.y_q);
      }
    }
  }
  return b;
}

std::string coverage_words(int filled, std::int64_t rows, std::size_t series) {
  return fmt::format("{} of {} bins of {:g}° hold samples (means over all {} fitted samples; the individual samples "
                     "shown on demand are {} of them, taken with an incommensurate stride).",
                     filled, kAngleBins, 360.0 / kAngleBins, rows, series);
}

Plot position_error(const DiscoveryRun& run, const std::vector<StepBins>& bins) {
  const std::size_t n = run.steps.size();
  const ModelFit& first = run.steps.front().fit;
  const ModelFit& last = run.steps.back().fit;
  Plot p = plot("pe", "Position error ε vs θ: measured (dots, ±1 σ band) over the model (line)",
                angle_axis(last.reference), axis("ε, position error", "arcmin", "eps_arcmin"));
  p.group = "theta";
  p.height = 320;
  p.angle_bins = kAngleBins;
  if (n > 1) {
    Series m = mean_line("model, step 1: " + model_name(first), step_color(0, n), bins.front().model.result(), 2.0);
    m.dashed = true;
    p.series.push_back(std::move(m));
  }
  p.series.push_back(mean_line(fmt::format("model, step {}: {}", n, model_name(last)), step_color(n - 1, n),
                               bins.back().model.result()));
  const AngleBins measured = bins.back().measured.result();
  p.filled_bins = measured.filled;
  p.series.push_back(band("measured: mean per 2° bin ± 1 σ", kMeasuredColor, measured));
  const ResidualSeries& s = last.series;
  p.series.push_back(samples("measured samples", kMeasuredColor, degrees(s.theta), scaled(s.eps_measured, kArcminPerRad)));
  p.caption = fmt::format(
      "Position error against {}: the line is the fitted model ε̂(θ), the dots the measured ε, both as means per bin, "
      "with a band of ±1 standard deviation of the samples in the bin. {}",
      last.reference ? "the reference encoder" : "the speed-smoothed ideal angle",
      coverage_words(measured.filled, bins.back().rows, s.theta.size()));
  return p;
}

Plot step_residual(const DiscoveryRun& run, std::size_t i, const StepBins& bins) {
  const ModelFit& f = run.steps[i].fit;
  const ResidualSeries& s = f.series;
  const std::string color = step_color(i, run.steps.size());
  Plot p = plot(fmt::format("res{}", i + 1), fmt::format("Step {}: residual of {} vs θ", i + 1, model_name(f)),
                angle_axis(f.reference), axis("residual ε − ε̂", "arcmin", "residual_arcmin"));
  p.group = "theta";
  p.height = 260;
  p.half = run.steps.size() > 1;
  p.angle_bins = kAngleBins;
  const AngleBins b = bins.residual.result();
  p.filled_bins = b.filled;
  p.series.push_back(band("residual: mean per 2° bin ± 1 σ", color, b));
  p.series.push_back(samples("residual samples", color, degrees(s.theta),
                             scaled(difference(s.eps_measured, s.eps_model), kArcminPerRad)));
  const double floor = rad_to_arcmin(f.noise_floor_rad);
  p.series.push_back(hline(fmt::format("± noise floor {:.3g} arcmin", floor), 0.0, 360.0, floor));
  p.series.push_back(hline("− noise floor", 0.0, 360.0, -floor));
  p.series.back().legend = false;
  const SignalResidual* pos = f.signals.empty() ? nullptr : &f.signals.front();
  p.caption = fmt::format(
      "What {} leaves of the position error: rms {:.3g} arcmin = {:.2f}x the floor{}. The band is the samples' spread "
      "(about the floor when the rest is noise); the dots are means of ~{} samples each, so structure a missing "
      "effect leaves stands out of the noise (the angle's quantization does not average down where the samples "
      "fall on the same angles every turn). {}",
      model_name(f), rad_to_arcmin(f.residual_rms_rad), f.residual_rms_rad / f.noise_floor_rad,
      pos != nullptr && std::isfinite(pos->held_back_rms)
          ? fmt::format(" (held back: {:.2f}x)", pos->held_back_rms / pos->floor)
          : std::string(),
      bins.rows / kAngleBins, coverage_words(b.filled, bins.rows, s.theta.size()));
  return p;
}

/// Residual amplitude by harmonic order, one set of dots per step (later steps smaller, so
/// an amplitude a step did not change shows as a ring of both colours), with the floor and a
/// fifth of it. per_step[i]: step i's harmonics; amplitudes x scale; orders below
/// first_order left out; amplitudes below the plot's range (floor x 1e-3) are not drawn.
Plot spectrum(const DiscoveryRun& run, std::string id, std::string title, Axis x, Axis y, double floor,
              const std::vector<std::vector<HarmonicResidual>>& per_step, double scale, int first_order) {
  Plot p = plot(std::move(id), std::move(title), std::move(x), std::move(y));
  p.y.log = true;
  p.height = 280;
  p.y.lo = floor * kSpectrumRangeBelowFloor;
  const std::size_t n = run.steps.size();
  for (std::size_t i = 0; i < n; ++i) {
    Series s = line(step_label(run, i), step_color(i, n), {}, {});
    s.mark = Mark::kPoints;
    s.width = std::max(5.0, 13.0 - 3.0 * static_cast<double>(i));  // [px] dot diameter
    for (const HarmonicResidual& h : per_step[i]) {
      if (h.order < first_order) continue;
      const double a = h.amplitude * scale;
      s.x.push_back(h.order);
      s.y.push_back(a >= p.y.lo ? a : kNaN);
    }
    p.series.push_back(std::move(s));
  }
  p.series.push_back(hline(fmt::format("noise floor (rms per sample) {:.3g} {}", floor, p.y.unit), p.x.lo, p.x.hi, floor));
  p.series.push_back(hline("a fifth of it: harmonics above are named in “where it fails”", p.x.lo, p.x.hi,
                           kNamedHarmonicShare * floor));
  p.series.back().color = "#999999";
  return p;
}

Plot by_bins(const DiscoveryRun& run, std::string id, std::string title, Axis x, bool speed) {
  Plot p = plot(std::move(id), std::move(title), std::move(x), axis("residual rms", "arcmin", "residual_rms_arcmin"));
  p.y.log = true;
  p.height = 280;
  p.half = true;
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    Series s = line(step_label(run, i), step_color(i, run.steps.size()), {}, {});
    s.mark = Mark::kLinePoints;
    const ModelFit& f = run.steps[i].fit;
    if (speed) {
      for (const auto& b : f.speed_bins) {
        s.x.push_back(b.rpm_mid);
        s.y.push_back(positive(rad_to_arcmin(b.rms)));
      }
    } else {
      for (const auto& b : f.time_bins) {
        s.x.push_back(0.5 * (b.t_lo + b.t_hi));
        s.y.push_back(positive(rad_to_arcmin(b.rms)));
      }
    }
    p.series.push_back(std::move(s));
  }
  const ModelFit& last = run.steps.back().fit;
  double lo = 0.0, hi = 1.0;
  if (speed && !last.speed_bins.empty()) {
    lo = std::min(last.speed_bins.front().rpm_mid, 0.0);
    hi = std::max(last.speed_bins.back().rpm_mid, 0.0);
    const double pad = std::max(0.1 * (hi - lo), 1.0);
    lo -= pad;
    hi += pad;
  } else if (!speed && !last.time_bins.empty()) {
    hi = last.time_bins.back().t_hi;
  }
  p.x.lo = lo;
  p.x.hi = hi;
  const double floor = rad_to_arcmin(last.noise_floor_rad);
  p.series.push_back(hline(fmt::format("noise floor {:.3g} arcmin", floor), lo, hi, floor));
  return p;
}

/// i_d or i_q vs theta_e: measured (reference frame) over the model's prediction.
Plot dq_panel(const ModelFit& f, const std::string& id, const std::string& name,
              const AngleBinner& measured_bins, const AngleBinner& model_bins, const std::vector<double>& samples_y) {
  const ResidualSeries& s = f.series;
  Plot p = plot(id, fmt::format("{} vs θ_e: measured (dots, ±1 σ band) over the model (line)", name), theta_e_axis(),
                axis(name + " in the reference frame", "A", name + "_a"));
  p.group = "theta_e";
  p.height = 280;
  p.half = true;
  p.angle_bins = kAngleBins;
  const AngleBins m = measured_bins.result();
  p.filled_bins = m.filled;
  p.series.push_back(mean_line("model: operating point + " + model_name(f), "#1f5fa8", model_bins.result()));
  p.series.push_back(band("measured: mean per 2° bin ± 1 σ", kMeasuredColor, m));
  p.series.push_back(samples("measured samples", kMeasuredColor, degrees(s.theta_e), samples_y));
  std::int64_t rows = 0;
  for (const double c : m.count) rows += static_cast<std::int64_t>(c);
  p.caption = fmt::format(
      "{} after the Park transform at the reference encoder's θ_e, against the motor electrical angle: current-sensor "
      "offsets show once per θ_e turn, gain mismatch twice, dead time six times. {}",
      name, coverage_words(m.filled, rows, s.theta_e.size()));
  return p;
}

/// What the R/D angle's error does to the dq currents, before and after compensation, vs theta.
Plot dq_angle_error(const ModelFit& f, const StepBins& bins) {
  Plot p = plot("dqerr", "The angle error in the currents: dq with the R/D angle minus dq with the reference angle",
                angle_axis(f.reference), axis("current difference", "mA", "delta_current_ma"));
  p.group = "theta";
  p.height = 280;
  p.angle_bins = kAngleBins;
  const AngleBins d_raw = bins.d_raw.result();
  p.filled_bins = d_raw.filled;
  p.series.push_back(mean_line("i_d, raw R/D angle", "#c0392b", d_raw, 2.0));
  p.series.push_back(mean_line("i_d, R/D angle compensated by the final model", "#1f5fa8", bins.d_comp.result(), 2.0));
  Series q_raw = mean_line("i_q, raw R/D angle", "#e67e22", bins.q_raw.result(), 1.5);
  q_raw.dashed = true;
  Series q_comp = mean_line("i_q, compensated", "#16a085", bins.q_comp.result(), 1.5);
  q_comp.dashed = true;
  p.series.push_back(std::move(q_raw));
  p.series.push_back(std::move(q_comp));
  std::int64_t rows = 0;
  for (const double c : d_raw.count) rows += static_cast<std::int64_t>(c);
  p.caption = fmt::format(
      "A drive that uses the R/D angle rotates its dq frame by the angle error (p/p_r)·ε: i_d moves by about "
      "i_q·(p/p_r)·ε. The raw line is that imprint of ε(θ), so it is plotted against θ; compensation by the final "
      "model's ε̂ should bring it to zero. {}",
      coverage_words(d_raw.filled, rows, f.series.theta.size()));
  return p;
}

void write_axis(std::string& o, const Axis& a) {
  o += fmt::format("{{\"label\":{},\"unit\":{},\"column\":{},\"log\":{},\"lo\":{},\"hi\":{},\"step\":{}}}",
                   json::str(a.label), json::str(a.unit), json::str(a.column), a.log, json::num(a.lo),
                   json::num(a.hi), json::num(a.step));
}

const char* mark_name(Mark m) {
  switch (m) {
    case Mark::kLine: return "line";
    case Mark::kPoints: return "points";
    case Mark::kLinePoints: return "linepoints";
    case Mark::kBand: return "band";
  }
  return "line";
}

}  // namespace

AngleBinner::AngleBinner(int bins, double scale)
    : scale_(scale),
      n_(static_cast<std::size_t>(std::max(bins, 1)), 0.0),
      sum_(n_.size(), 0.0),
      sum2_(n_.size(), 0.0),
      angle_sum_(n_.size(), 0.0) {}

void AngleBinner::add(double angle, double y) {
  const double v = y * scale_;
  if (!std::isfinite(angle) || !std::isfinite(v)) return;
  const double a = wrap_2pi(angle);
  const std::size_t nb = n_.size();
  const auto k = std::min(static_cast<std::size_t>(a / kTwoPi * static_cast<double>(nb)), nb - 1);
  n_[k] += 1.0;
  sum_[k] += v;
  sum2_[k] += v * v;
  angle_sum_[k] += a;
}

AngleBins AngleBinner::result() const {
  AngleBins b;
  const std::size_t nb = n_.size();
  b.centre.resize(nb);
  b.mean.assign(nb, kNaN);
  b.sd.assign(nb, kNaN);
  b.count = n_;
  for (std::size_t k = 0; k < nb; ++k) {
    const double n = n_[k];
    b.centre[k] = n > 0.0 ? rad_to_deg(angle_sum_[k] / n) : (static_cast<double>(k) + 0.5) * 360.0 / static_cast<double>(nb);
    if (n == 0.0) continue;
    ++b.filled;
    b.mean[k] = sum_[k] / n;
    // Population spread of the bin's samples (one sample: 0); the clamp absorbs rounding.
    b.sd[k] = std::sqrt(std::max(0.0, sum2_[k] / n - b.mean[k] * b.mean[k]));
  }
  return b;
}

AngleBins bin_by_angle(std::span<const double> angle, std::span<const double> y, int bins, double scale) {
  AngleBinner b(bins, scale);
  for (std::size_t i = 0; i < angle.size() && i < y.size(); ++i) b.add(angle[i], y[i]);
  return b.result();
}

std::string bare_unit(std::string_view unit) {
  if (unit.size() >= 2 && unit.front() == '[' && unit.back() == ']') unit = unit.substr(1, unit.size() - 2);
  return std::string(unit);
}

std::vector<Plot> report_plots(const DiscoveryRun& run) {
  const auto per_step = [&run](const auto& of) {
    std::vector<std::vector<HarmonicResidual>> out;
    for (const Explanation& ex : run.steps) out.push_back(of(ex.fit));
    return out;
  };
  std::vector<Plot> plots;
  const ModelFit& last = run.steps.back().fit;
  std::vector<StepBins> bins;
  if (run.log) {
    for (const Explanation& ex : run.steps) bins.push_back(bin_rows(*run.log, ex.fit));
    plots.push_back(position_error(run, bins));
    for (std::size_t i = 0; i < run.steps.size(); ++i) plots.push_back(step_residual(run, i, bins[i]));
  }
  const double floor_arcmin = rad_to_arcmin(last.noise_floor_rad);
  const int orders = last.harmonics.empty() ? 0 : last.harmonics.back().order;
  plots.push_back(spectrum(
      run, "spec", "Position-error residual by harmonic of θ, per step",
      order_axis("θ (resolver electrical)", "order_theta", 0, orders), axis("amplitude", "arcmin", "amplitude_arcmin"),
      floor_arcmin, per_step([](const ModelFit& f) { return f.harmonics; }), kArcminPerRad, 0));
  plots.back().caption =
      "Amplitude of each harmonic of the position-error residual at each step (log scale; amplitudes below the "
      "plot's range, a thousandth of the floor, are not drawn). A missing effect shows as a harmonic above the floor "
      "that drops in the step that adds it.";
  if (!last.harmonics_mech.empty()) {
    const int m_orders = last.harmonics_mech.back().order;
    plots.push_back(spectrum(
        run, "specm", "Position-error residual by harmonic of θ_m (mechanical), per step",
        order_axis("θ_m (mechanical)", "order_theta_m", 0, m_orders), axis("amplitude", "arcmin", "amplitude_arcmin"),
        floor_arcmin, per_step([](const ModelFit& f) { return f.harmonics_mech; }), kArcminPerRad, 0));
    plots.back().caption =
        "The same residual by harmonic of the mechanical angle: eccentricity and the encoder coupling show once and "
        "twice per mechanical turn, at orders of θ that are not whole numbers when p_r > 1.";
  }
  const SignalResidual* dq = nullptr;
  for (const auto& s : last.signals) {
    if (s.signal == "i_dq") dq = &s;
  }
  if (last.currents_used && dq != nullptr && !last.harmonics_id.empty()) {
    // |i_d, i_q| per order [mA]; order 0 is the operating point (the dq nuisance), not shown.
    const auto combined = per_step([](const ModelFit& f) {
      std::vector<HarmonicResidual> c;
      for (std::size_t k = 0; k < f.harmonics_id.size() && k < f.harmonics_iq.size(); ++k) {
        c.push_back({f.harmonics_id[k].order, std::hypot(f.harmonics_id[k].amplitude, f.harmonics_iq[k].amplitude), 0.0});
      }
      return c;
    });
    const int dq_orders = combined.back().empty() ? 0 : combined.back().back().order;
    plots.push_back(spectrum(run, "specdq", "i_d, i_q residual by harmonic of θ_e, per step",
                             order_axis("θ_e (motor electrical)", "order_theta_e", 1, dq_orders),
                             axis("amplitude √(A_d² + A_q²)", "mA", "amplitude_ma"), 1e3 * dq->floor, combined, 1e3, 1));
    plots.back().caption =
        "The dq-current residual by harmonic of the motor electrical angle: current-sensor offsets show at 1θ_e, gain "
        "mismatch at 2θ_e, dead time at 6θ_e. Order 0 is the operating point the fit takes as given, not shown.";
  }
  // One speed bin is one dot: not a breakdown (single_breakdown_notes says so on the page).
  const bool speeds = last.speed_bins.size() > 1;
  if (speeds) {
    plots.push_back(by_bins(run, "speed", "Position-error residual vs speed, per step",
                            axis("speed, mechanical", "r/min", "speed_rpm"), true));
    plots.back().caption = fmt::format(
        "Residual rms in {} speed bins (empty bins dropped). A residual that grows with speed points at sampling skew "
        "or the R/D tracking loop.",
        last.speed_bins.size());
  }
  plots.push_back(by_bins(run, "time", "Position-error residual vs time, per step",
                          axis("time from the log's first sample", "s", "t_s"), false));
  plots.back().half = speeds;
  plots.back().caption = fmt::format(
      "Residual rms in {} equal windows of the log. No catalog effect changes with time: a residual that changes "
      "from window to window at the same speed is a drift outside the catalog (e.g. with temperature).",
      last.time_bins.size());
  if (run.log && run.log->currents) {
    const StepBins& b = bins.back();
    plots.push_back(dq_panel(last, "dqd", "i_d", b.d, b.d_model, last.series.i_d_ref));
    plots.push_back(dq_panel(last, "dqq", "i_q", b.q, b.q_model, last.series.i_q_ref));
    if (run.log->rd) plots.push_back(dq_angle_error(last, b));
  }
  lead_with_failing_signal(run, plots);
  return plots;
}

const SignalResidual* failing_signal(const DiscoveryRun& run) {
  const Explanation& last = run.steps.back();
  if (last.verdict == Verdict::kExplained) return nullptr;
  const SignalResidual* worst = nullptr;
  for (const SignalResidual& s : last.fit.signals) {
    if (!(s.floor > 0.0) || !std::isfinite(s.rms / s.floor)) continue;
    if (worst == nullptr || s.rms / s.floor > worst->rms / worst->floor) worst = &s;
  }
  return worst;
}

void lead_with_failing_signal(const DiscoveryRun& run, std::vector<Plot>& plots) {
  const SignalResidual* worst = failing_signal(run);
  if (worst == nullptr) return;
  // The position-error plot already leads; sin/cos share it (the angle they give).
  std::vector<std::string> ids{"pe"};
  if (worst->signal == "i_dq") ids = {"specdq", "dqd"};
  for (const std::string& id : ids) {
    const auto it = std::find_if(plots.begin(), plots.end(), [&id](const Plot& p) { return p.id == id; });
    if (it == plots.end()) continue;
    if (it == plots.begin()) return;
    Plot lead = std::move(*it);
    plots.erase(it);
    if (lead.half) {
      // Its partner (dqd's dqq) is alone now: full width.
      lead.half = false;
      for (Plot& p : plots) {
        if (p.id == "dqq") p.half = false;
      }
    }
    lead.caption = fmt::format("Shown first: {} is the signal furthest above its floor ({:.2f}x), where the model "
                               "fails most. ",
                               worst->signal, worst->rms / worst->floor) +
                   lead.caption;
    plots.insert(plots.begin(), std::move(lead));
    return;
  }
}

std::string one_speed_note(const ModelFit& f) {
  if (f.speed_bins.size() != 1) return {};
  return fmt::format("One speed: the speed breakdown has one bin ({:.0f} r/min, {} samples), so it shows no "
                                "dependence on speed and residual vs speed is not drawn; effects that grow with speed "
                                "(sampling skew, the R/D tracking loop) need a log at several speeds.",
                                f.speed_bins.front().rpm_mid, f.speed_bins.front().samples);
}

std::string one_direction_note(const ModelFit& f) {
  if (f.directions.size() != 1) return {};
  return fmt::format("One direction: every fitted sample turned {}, so the direction breakdown has one row "
                                "and cannot show backlash or a delay (an offset that flips with the direction needs "
                                "an out-and-back).",
                                f.directions.front().direction > 0 ? "forward" : "backward");
}

std::string plots_json(const std::vector<Plot>& plots) {
  std::string o = "[";
  for (std::size_t i = 0; i < plots.size(); ++i) {
    const Plot& p = plots[i];
    o += i > 0 ? ",\n" : "";
    o += fmt::format("{{\"id\":{},\"group\":{},\"title\":{},\"height\":{},\"half\":{},\"angle_bins\":{},"
                     "\"filled_bins\":{},\"x\":",
                     json::str(p.id), json::str(p.group), json::str(p.title), p.height, p.half, p.angle_bins,
                     p.filled_bins);
    write_axis(o, p.x);
    o += ",\"y\":";
    write_axis(o, p.y);
    o += ",\"series\":[";
    for (std::size_t k = 0; k < p.series.size(); ++k) {
      const Series& s = p.series[k];
      o += k > 0 ? ",\n" : "\n";
      o += fmt::format("{{\"label\":{},\"color\":{},\"mark\":\"{}\",\"dashed\":{},\"hidden\":{},\"legend\":{},"
                       "\"width\":{},\"x\":{},\"y\":{}",
                       json::str(s.label), json::str(s.color), mark_name(s.mark), s.dashed, s.hidden, s.legend,
                       json::num(s.width), json::array(s.x, s.digits), json::array(s.y, s.digits));
      if (s.mark == Mark::kBand) {
        o += ",\"spread\":" + json::array(s.spread, s.digits) + ",\"count\":" + json::array(s.count, 9);
      }
      if (!s.error.empty()) o += ",\"err\":" + json::array(s.error, 3);
      if (!s.names.empty()) {
        o += ",\"names\":[";
        for (std::size_t n = 0; n < s.names.size(); ++n) o += (n > 0 ? "," : "") + json::str(s.names[n]);
        o += "]";
      }
      if (s.label_points) o += ",\"label_points\":true";
      o += "}";
    }
    o += "]}";
  }
  return o + "]";
}

}  // namespace resolver::report
