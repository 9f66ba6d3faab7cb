#include "tools/model/model_report.h"

#include <fmt/format.h>

#include <cmath>

#include "daemon/core/angles.h"
#include "drivers/text/json_string.h"

namespace resolver {

namespace {

std::string json_str(std::string_view s) { return text::json_string(s); }

std::string json_num(double v) { return std::isfinite(v) ? fmt::format("{:.9g}", v) : "null"; }

/// The items of v as JSON, comma-separated (without the brackets).
template <typename T, typename Item>
std::string json_items(const std::vector<T>& v, Item&& item) {
  std::string o;
  for (std::size_t i = 0; i < v.size(); ++i) o += (i ? "," : "") + item(v[i]);
  return o;
}

/// The model, what the fit covers, the notes and the parameters.
std::string text_header(const ModelFit& f, const std::vector<std::string>& notes) {
  const SampleAccount& a = f.account;
  std::string o;
  o += fmt::format("model: {}\n", f.effects.empty() ? std::string("(none)") : fmt::format("{}", fmt::join(f.effects, ", ")));
  o += fmt::format("position error against {}\n", f.reference ? "the reference encoder" : "the self-calibrated ideal angle");
  o += fmt::format(
      "covers: {} of {} samples fitted (moving; {} at standstill, {} outliers, {} excluded), {:.3g} s, {:.3g} "
      "electrical ({:.3g} mechanical) revolutions travelled, {} reversal{}, {} standstill{}; units: {}\n",
      a.fitted, a.samples_in, a.standstill, a.outliers, a.excluded, a.span_s, a.revolutions_electrical,
      a.revolutions_mechanical, a.reversals, a.reversals == 1 ? "" : "s", a.standstills, a.standstills == 1 ? "" : "s",
      a.units);
  for (const auto& n : notes) o += "note: " + n + "\n";
  for (const auto& n : f.notes) o += "note: " + n + "\n";
  o += fmt::format("\nparameters (value +- standard error, {}):\n", std_error_basis(f));
  for (const auto& p : f.params) {
    o += fmt::format("  {:<36} {:>12.5g} +- {:.2g} {}\n", p.name, p.value, p.std_error, p.unit);
  }
  return o;
}

/// Each signal's residual against its floor, where the floors come from, the folds,
/// the whiteness test and the outliers.
std::string text_residuals(const ModelFit& f) {
  std::string o = "\nresidual rms vs noise floor (held back: fitted on one fold, evaluated on the other):\n";
  for (const auto& s : f.signals) {
    const bool rad = s.signal == "position_error";
    const std::string unit = s.signal == "i_dq" ? " A" : " of the amplitude";
    // NaN: not computed for this signal (no folds, or a position error derived from sin/cos).
    const auto or_na = [](double v, const char* spec) {
      return std::isfinite(v) ? fmt::format(fmt::runtime(spec), v) : std::string("n/a");
    };
    o += fmt::format("  {:<15} {:.3g}{} (before: {}), floor {:.3g}{} -> {:.2f}x floor; held back {}\n", s.signal,
                     s.rms, rad ? fmt::format(" rad = {:.3g} arcmin", rad_to_arcmin(s.rms)) : unit,
                     or_na(s.raw_rms, "{:.3g}"), s.floor,
                     rad ? fmt::format(" rad = {:.3g} arcmin", rad_to_arcmin(s.floor)) : std::string(""),
                     s.rms / s.floor, or_na(s.held_back_rms / s.floor, "{:.2f}x"));
  }
  auto floor_line = [&](const char* name, const FloorEstimate& e) {
    if (e.source.empty() || e.source == "none") return;
    o += fmt::format("  floor {:<13} from {} ({:.3g}; second differences {:.3g}, standstill {:.3g} over {} samples, "
                     "quantization {:.3g})\n",
                     name, e.source, e.chosen, e.second_difference, e.standstill, e.standstill_samples, e.quantization);
  };
  floor_line("position", f.floors.rd);
  floor_line("sin/cos", f.floors.sc);
  floor_line("i_dq", f.floors.cur);
  o += fmt::format("  held-back folds: {}\n", f.account.fold_rule);
  if (f.whiteness.lags > 0) {
    o += fmt::format("  whiteness: autocorrelation at lags 1..{} within +-{:.3g} (99 %): {} outside, largest {:.3g}\n",
                     f.whiteness.lags, f.whiteness.band, f.whiteness.outside, f.whiteness.max_abs);
  }
  for (const auto& out : f.outliers) {
    o += fmt::format("  outliers on {}: {} (largest {:.3g}), kept out of the fit\n", out.signal, out.count, out.largest);
  }
  return o;
}

/// The residual by harmonic order of theta, theta_m and (i_d / i_q) theta_e.
std::string text_harmonics(const ModelFit& f) {
  std::string o = "\nposition-error residual by harmonic order of theta [rad]:\n ";
  for (const auto& h : f.harmonics) o += fmt::format(" {}:{:.2g}", h.order, h.amplitude);
  if (!f.harmonics_mech.empty()) {
    o += "\nby harmonic order of theta_m [rad]:\n ";
    for (const auto& h : f.harmonics_mech) o += fmt::format(" {}:{:.2g}", h.order, h.amplitude);
  }
  if (f.currents_used) {
    o += "\ni_d / i_q residual by harmonic order of theta_e [A]:\n ";
    for (std::size_t n = 0; n < f.harmonics_id.size() && n < f.harmonics_iq.size(); ++n) {
      o += fmt::format(" {}:{:.2g}/{:.2g}", n, f.harmonics_id[n].amplitude, f.harmonics_iq[n].amplitude);
    }
  }
  return o;
}

/// The residual by speed bin, direction and time window.
std::string text_bins(const ModelFit& f) {
  std::string o = "\n\nby speed bin (moving samples):\n";
  for (const auto& b : f.speed_bins) {
    o += fmt::format("  {:>7.0f} r/min  {:>7} samples  rms {:.3g} rad ({:.2f}x floor), 2theta {}\n", b.rpm_mid,
                     b.samples, b.rms, b.rms / f.noise_floor_rad,
                     std::isfinite(b.order2_amplitude) ? fmt::format("{:.3g} rad", b.order2_amplitude)
                                                       : std::string("- (the bin does not cover a turn)"));
  }
  o += "\nby direction:\n";
  for (const auto& d : f.directions) {
    o += fmt::format("  {:<9} {:>7} samples  rms {:.3g} rad ({:.2f}x floor), mean {:.3g} rad\n",
                     d.direction > 0 ? "forward" : "backward", d.samples, d.rms, d.rms / f.noise_floor_rad, d.mean);
  }
  o += "\nby time window:\n";
  for (const auto& b : f.time_bins) {
    o += fmt::format("  {:>7.2f}-{:<7.2f} s  rms {:.3g} rad ({:.2f}x floor), mean {:.3g} rad\n", b.t_lo, b.t_hi,
                     b.rms, b.rms / f.noise_floor_rad, b.mean);
  }
  return o;
}

/// explain's part: where the model fails, the ranked candidates, the verdict and a suggested custom effect.
std::string text_explanation(const Explanation& ex) {
  const ModelFit& f = ex.fit;
  std::string o;
  if (!ex.where_it_fails.empty()) {
    o += "\nwhere it fails:\n";
    for (const auto& w : ex.where_it_fails) o += "  - " + w + "\n";
  }
  if (ex.candidates.empty() && ex.not_evaluated.empty()) {
    o += "\ncandidates: none ranked\n";
  } else {
    o += "\ncandidates (lowest BIC first; * = proposed; ERR = share of the residual it removes):\n";
  }
  for (const auto& c : ex.candidates) {
    const std::string dq = f.currents_used ? fmt::format(", i_dq {:.3g} A", c.dq_residual_after) : std::string();
    if (!c.replaces.empty()) o += fmt::format("  {} in place of {}:\n", c.proposed ? '*' : ' ', c.replaces);
    o += fmt::format("  {} {:<26} residual {:.3g} rad ({:.2f}x floor){}  BIC {:.1f} (drop {:.1f}) ERR {:.3f}{}\n      {}\n",
                     c.proposed ? '*' : ' ', c.effect, c.residual_after_rad, c.residual_after_rad / f.noise_floor_rad,
                     dq, c.score, c.bic_drop, c.err, c.reaches_floor ? "  reaches the floor" : "", c.reason);
    if (c.stepped) o += std::string(kOneStepNote);
    if (!c.fits_as_well.empty()) o += fmt::format("      fits as well here: {}\n", fmt::join(c.fits_as_well, ", "));
  }
  for (const auto& n : ex.not_evaluated) o += "    not evaluated: " + n + "\n";
  o += fmt::format("\nverdict: {}\n{}\n", to_string(ex.verdict), ex.summary);
  if (!ex.suggested_custom.empty()) o += "\nsuggested custom effect (paste into the config):\n" + ex.suggested_custom;
  return o;
}

/// "effects" .. "floors": the model, its parameters, the residual and floor, what the fit covers.
std::string json_fit_head(const ModelFit& f) {
  std::string o = "{\"effects\":[" + json_items(f.effects, json_str);
  o += "],\"params\":{" + json_items(f.params, [](const auto& p) {
    return json_str(p.name) + ":{\"value\":" + json_num(p.value) + ",\"stderr\":" + json_num(p.std_error) +
           ",\"unit\":" + json_str(p.unit) + "}";
  });
  o += "},\"residual_rms_rad\":" + json_num(f.residual_rms_rad);
  o += ",\"residual_rms_arcmin\":" + json_num(rad_to_arcmin(f.residual_rms_rad));
  o += ",\"noise_floor_rad\":" + json_num(f.noise_floor_rad);
  o += ",\"reference\":" + std::string(f.reference ? "true" : "false");
  const SampleAccount& a = f.account;
  o += fmt::format(",\"covers\":{{\"samples_in\":{},\"rows\":{},\"fitted\":{},\"moving\":{},\"standstill\":{},"
                   "\"outliers\":{},\"excluded\":{},\"without_angle\":{},\"without_reference\":{},\"span_s\":{},"
                   "\"revolutions_electrical\":{},\"revolutions_mechanical\":{},\"reversals\":{},"
                   "\"standstills\":{},\"fold_rule\":{},\"units\":{}}}",
                   a.samples_in, a.rows, a.fitted, a.moving, a.standstill, a.outliers, a.excluded, a.without_angle,
                   a.without_reference, json_num(a.span_s), json_num(a.revolutions_electrical),
                   json_num(a.revolutions_mechanical), a.reversals, a.standstills, json_str(a.fold_rule),
                   json_str(a.units));
  auto floor_json = [&](const FloorEstimate& e) {
    return fmt::format("{{\"value\":{},\"source\":{},\"second_differences\":{},\"standstill\":{},"
                       "\"standstill_samples\":{},\"quantization\":{}}}",
                       json_num(e.chosen), json_str(e.source), json_num(e.second_difference), json_num(e.standstill),
                       e.standstill_samples, json_num(e.quantization));
  };
  o += ",\"floors\":{\"position_error\":" + floor_json(f.floors.rd) + ",\"sin_cos\":" + floor_json(f.floors.sc) +
       ",\"i_dq\":" + floor_json(f.floors.cur) + "}";
  return o;
}

/// "outliers" .. "harmonics_mech": how far the fit can be trusted and the residual by direction.
std::string json_diagnostics(const ModelFit& f) {
  std::string o = ",\"outliers\":[" + json_items(f.outliers, [](const auto& x) {
    return fmt::format("{{\"signal\":{},\"count\":{},\"largest\":{},\"first_times_s\":[{}]}}", json_str(x.signal),
                       x.count, json_num(x.largest), fmt::join(x.times, ","));
  });
  o += "],\"residual_with_outliers_rad\":" + json_num(f.rms_with_outliers_rad);
  o += fmt::format(",\"whiteness\":{{\"lags\":{},\"band\":{},\"max_abs\":{},\"outside\":{},\"samples\":{}}}",
                   f.whiteness.lags, json_num(f.whiteness.band), json_num(f.whiteness.max_abs), f.whiteness.outside,
                   f.whiteness.samples);
  o += ",\"robust_standard_errors\":" + std::string(f.robust_errors ? "true" : "false");
  o += ",\"standard_errors\":" + json_str(std_error_basis(f));
  o += ",\"passes\":" + std::to_string(f.passes);
  o += ",\"directions\":[" + json_items(f.directions, [](const auto& d) {
    return fmt::format("{{\"direction\":{},\"samples\":{},\"rms_rad\":{},\"mean_rad\":{}}}", d.direction, d.samples,
                       json_num(d.rms), json_num(d.mean));
  });
  o += "],\"harmonics_mech\":[" + json_items(f.harmonics_mech, [](const auto& h) {
    return fmt::format("{{\"order\":{},\"amplitude_rad\":{},\"phase_rad\":{}}}", h.order, json_num(h.amplitude),
                       json_num(h.phase));
  });
  return o + "]";
}

/// "signals" .. "time_bins": the residual per signal, by harmonic, speed and time.
std::string json_breakdowns(const ModelFit& f) {
  std::string o = ",\"signals\":[" + json_items(f.signals, [](const auto& s) {
    return fmt::format("{{\"signal\":{},\"rms\":{},\"floor\":{},\"raw_rms\":{},\"held_back_rms\":{},\"rows\":{}}}",
                       json_str(s.signal), json_num(s.rms), json_num(s.floor), json_num(s.raw_rms),
                       json_num(s.held_back_rms), s.rows);
  });
  o += "],\"harmonics\":[" + json_items(f.harmonics, [](const auto& h) {
    return fmt::format("{{\"order\":{},\"amplitude_rad\":{},\"phase_rad\":{}}}", h.order, json_num(h.amplitude),
                       json_num(h.phase));
  });
  o += "],\"harmonics_dq\":[";
  for (std::size_t i = 0; i < f.harmonics_id.size() && i < f.harmonics_iq.size(); ++i) {
    o += (i ? "," : "") + fmt::format("{{\"order_theta_e\":{},\"i_d_amplitude_a\":{},\"i_q_amplitude_a\":{}}}",
                                      f.harmonics_id[i].order, json_num(f.harmonics_id[i].amplitude),
                                      json_num(f.harmonics_iq[i].amplitude));
  }
  o += "],\"speed_bins\":[" + json_items(f.speed_bins, [](const auto& b) {
    return fmt::format("{{\"rpm\":{},\"samples\":{},\"rms_rad\":{},\"order2_rad\":{}}}", json_num(b.rpm_mid),
                       b.samples, json_num(b.rms), json_num(b.order2_amplitude));
  });
  o += "],\"time_bins\":[" + json_items(f.time_bins, [](const auto& b) {
    return fmt::format("{{\"t_lo_s\":{},\"t_hi_s\":{},\"samples\":{},\"rms_rad\":{},\"order2_rad\":{}}}",
                       json_num(b.t_lo), json_num(b.t_hi), b.samples, json_num(b.rms), json_num(b.order2_amplitude));
  });
  return o + "]";
}

/// One ranked candidate as a JSON object.
std::string json_candidate(const Candidate& c) {
  return fmt::format("{{\"effect\":{},\"residual_after_rad\":{},\"dq_residual_after_a\":{},"
                     "\"score\":{},\"bic_drop\":{},\"err\":{},"
                     "\"proposed\":{},\"reaches_floor\":{},\"one_step\":{},\"replaces\":{},\"reason\":{},"
                     "\"fits_as_well\":[{}],\"params\":{{",
                     json_str(c.effect), json_num(c.residual_after_rad), json_num(c.dq_residual_after),
                     json_num(c.score), json_num(c.bic_drop), json_num(c.err), c.proposed, c.reaches_floor, c.stepped,
                     c.replaces.empty() ? std::string("null") : json_str(c.replaces), json_str(c.reason),
                     json_items(c.fits_as_well, json_str)) +
         json_items(c.params,
                    [](const auto& p) {
                      return json_str(p.name) + ":{\"value\":" + json_num(p.value) +
                             ",\"stderr\":" + json_num(p.std_error) + "}";
                    }) +
         "}}";
}

/// explain's members: the candidates, where the model fails, the verdict and a suggested custom effect.
std::string json_explanation(const Explanation& ex) {
  std::string o = ",\"candidates\":[" + json_items(ex.candidates, json_candidate);
  o += "],\"where_it_fails\":[" + json_items(ex.where_it_fails, json_str);
  o += "],\"missing_pair\":[" + json_items(ex.missing_pair, json_str);
  o += "],\"not_evaluated\":[" + json_items(ex.not_evaluated, json_str);
  o += "],\"verdict\":" + json_str(to_string(ex.verdict)) + ",\"summary\":" + json_str(ex.summary);
  o += ",\"suggested_custom\":" + (ex.suggested_custom.empty() ? std::string("null") : json_str(ex.suggested_custom));
  return o;
}

}  // namespace

std::string format_model_text(const Explanation& ex, bool explain, const std::vector<std::string>& notes) {
  const ModelFit& f = ex.fit;
  std::string o = text_header(f, notes) + text_residuals(f) + text_harmonics(f) + text_bins(f);
  if (!explain) {
    o += fmt::format("\nverdict: {}\n", f.explained ? "explained (every signal at its floor, held back too)"
                                                     : "not explained: run `resolver-model explain` for why");
    return o;
  }
  return o + text_explanation(ex);
}

std::string format_model_json(const Explanation& ex, bool explain, const std::vector<std::string>& notes,
                              const std::string& extra_members) {
  const ModelFit& f = ex.fit;
  std::string o = json_fit_head(f) + json_diagnostics(f) + json_breakdowns(f);
  std::vector<std::string> all = notes;
  all.insert(all.end(), f.notes.begin(), f.notes.end());
  o += ",\"bic\":" + json_num(f.bic) + ",\"notes\":[" + json_items(all, json_str) + "]";
  if (explain) {
    o += json_explanation(ex);
  } else {
    o += std::string(",\"verdict\":") + (f.explained ? "\"explained\"" : "\"not_explained\"");
  }
  return o + extra_members + "}\n";
}

}  // namespace resolver
