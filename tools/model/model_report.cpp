#include "tools/model/model_report.h"

#include <fmt/format.h>

#include <cmath>

#include "daemon/core/angles.h"

namespace resolver {

namespace {

std::string json_str(std::string_view s) {
  std::string o = "\"";
  for (char ch : s) {
    switch (ch) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) o += fmt::format("\\u{:04x}", static_cast<int>(ch));
        else o += ch;
    }
  }
  return o + "\"";
}

std::string json_num(double v) { return std::isfinite(v) ? fmt::format("{:.9g}", v) : "null"; }

}  // namespace

std::string format_model_text(const Explanation& ex, bool explain, const std::vector<std::string>& notes) {
  const ModelFit& f = ex.fit;
  std::string o;
  o += fmt::format("model: {}\n", f.effects.empty() ? std::string("(none)") : fmt::format("{}", fmt::join(f.effects, ", ")));
  o += fmt::format("position error against {}\n", f.reference ? "the reference encoder" : "the speed-smoothed ideal angle");
  for (const auto& n : notes) o += "note: " + n + "\n";
  for (const auto& n : f.notes) o += "note: " + n + "\n";
  o += "\nparameters (value +- standard error):\n";
  for (const auto& p : f.params) o += fmt::format("  {:<36} {:>12.4g} +- {:.2g}\n", p.name, p.value, p.std_error);
  o += "\nresidual rms vs noise floor:\n";
  for (const auto& s : f.signals) {
    const bool rad = s.signal == "position_error";
    const std::string unit = s.signal == "i_dq" ? " A" : " of the amplitude";
    o += fmt::format("  {:<15} {:.3g}{} (before: {:.3g}), floor {:.3g}{} -> {:.2f}x floor\n", s.signal, s.rms,
                     rad ? fmt::format(" rad = {:.3g} arcmin", rad_to_arcmin(s.rms)) : unit, s.raw_rms,
                     s.floor, rad ? fmt::format(" rad = {:.3g} arcmin", rad_to_arcmin(s.floor)) : std::string(""),
                     s.rms / s.floor);
  }
  o += "  (floor: rms of second differences of a saturated per-speed Fourier fit's residual / sqrt 6)\n";
  o += "\nposition-error residual by harmonic order of theta [rad]:\n ";
  for (const auto& h : f.harmonics) o += fmt::format(" {}:{:.2g}", h.order, h.amplitude);
  if (f.currents_used) {
    o += "\ni_d / i_q residual by harmonic order of theta_e [A]:\n ";
    for (std::size_t n = 0; n < f.harmonics_id.size() && n < f.harmonics_iq.size(); ++n) {
      o += fmt::format(" {}:{:.2g}/{:.2g}", n, f.harmonics_id[n].amplitude, f.harmonics_iq[n].amplitude);
    }
  }
  o += "\n\nby speed bin:\n";
  for (const auto& b : f.speed_bins) {
    o += fmt::format("  {:>7.0f} r/min  {:>7} samples  rms {:.3g} rad ({:.2f}x floor), 2theta {:.3g} rad\n", b.rpm_mid,
                     b.samples, b.rms, b.rms / f.noise_floor_rad, b.order2_amplitude);
  }
  o += "\nby time window:\n";
  for (const auto& b : f.time_bins) {
    o += fmt::format("  {:>7.2f}-{:<7.2f} s  rms {:.3g} rad ({:.2f}x floor), 2theta {:.3g} rad\n", b.t_lo, b.t_hi, b.rms,
                     b.rms / f.noise_floor_rad, b.order2_amplitude);
  }
  if (!explain) return o;
  if (!ex.where_it_fails.empty()) {
    o += "\nwhere it fails:\n";
    for (const auto& w : ex.where_it_fails) o += "  - " + w + "\n";
  }
  o += "\ncandidates (lowest BIC first; * = proposed):\n";
  for (const auto& c : ex.candidates) {
    const std::string dq = f.currents_used ? fmt::format(", i_dq {:.3g} A", c.dq_residual_after) : std::string();
    o += fmt::format("  {} {:<22} residual {:.3g} rad ({:.2f}x floor){}  BIC {:.1f} (drop {:.1f}){}\n      {}\n",
                     c.proposed ? '*' : ' ', c.effect, c.residual_after_rad, c.residual_after_rad / f.noise_floor_rad,
                     dq, c.score, c.bic_drop, c.reaches_floor ? "  reaches the floor" : "", c.reason);
  }
  for (const auto& n : ex.not_evaluated) o += "    not evaluated: " + n + "\n";
  o += fmt::format("\nverdict: {}\n{}\n", to_string(ex.verdict), ex.summary);
  return o;
}

std::string format_model_json(const Explanation& ex, bool explain, const std::vector<std::string>& notes) {
  const ModelFit& f = ex.fit;
  std::string o = "{\"effects\":[";
  for (std::size_t i = 0; i < f.effects.size(); ++i) o += (i ? "," : "") + json_str(f.effects[i]);
  o += "],\"params\":{";
  for (std::size_t i = 0; i < f.params.size(); ++i) {
    o += (i ? "," : "") + json_str(f.params[i].name) + ":{\"value\":" + json_num(f.params[i].value) +
         ",\"stderr\":" + json_num(f.params[i].std_error) + "}";
  }
  o += "},\"residual_rms_rad\":" + json_num(f.residual_rms_rad);
  o += ",\"residual_rms_arcmin\":" + json_num(rad_to_arcmin(f.residual_rms_rad));
  o += ",\"noise_floor_rad\":" + json_num(f.noise_floor_rad);
  o += ",\"reference\":" + std::string(f.reference ? "true" : "false");
  o += ",\"signals\":[";
  for (std::size_t i = 0; i < f.signals.size(); ++i) {
    const auto& s = f.signals[i];
    o += (i ? "," : "") + fmt::format("{{\"signal\":{},\"rms\":{},\"floor\":{},\"raw_rms\":{},\"rows\":{}}}",
                                      json_str(s.signal), json_num(s.rms), json_num(s.floor), json_num(s.raw_rms), s.rows);
  }
  o += "],\"harmonics\":[";
  for (std::size_t i = 0; i < f.harmonics.size(); ++i) {
    o += (i ? "," : "") + fmt::format("{{\"order\":{},\"amplitude_rad\":{},\"phase_rad\":{}}}", f.harmonics[i].order,
                                      json_num(f.harmonics[i].amplitude), json_num(f.harmonics[i].phase));
  }
  o += "],\"harmonics_dq\":[";
  for (std::size_t i = 0; i < f.harmonics_id.size() && i < f.harmonics_iq.size(); ++i) {
    o += (i ? "," : "") + fmt::format("{{\"order_theta_e\":{},\"i_d_amplitude_a\":{},\"i_q_amplitude_a\":{}}}",
                                      f.harmonics_id[i].order, json_num(f.harmonics_id[i].amplitude),
                                      json_num(f.harmonics_iq[i].amplitude));
  }
  o += "],\"speed_bins\":[";
  for (std::size_t i = 0; i < f.speed_bins.size(); ++i) {
    const auto& b = f.speed_bins[i];
    o += (i ? "," : "") + fmt::format("{{\"rpm\":{},\"samples\":{},\"rms_rad\":{},\"order2_rad\":{}}}", json_num(b.rpm_mid),
                                      b.samples, json_num(b.rms), json_num(b.order2_amplitude));
  }
  o += "],\"time_bins\":[";
  for (std::size_t i = 0; i < f.time_bins.size(); ++i) {
    const auto& b = f.time_bins[i];
    o += (i ? "," : "") + fmt::format("{{\"t_lo_s\":{},\"t_hi_s\":{},\"samples\":{},\"rms_rad\":{},\"order2_rad\":{}}}",
                                      json_num(b.t_lo), json_num(b.t_hi), b.samples, json_num(b.rms),
                                      json_num(b.order2_amplitude));
  }
  o += "],\"bic\":" + json_num(f.bic) + ",\"notes\":[";
  std::vector<std::string> all = notes;
  all.insert(all.end(), f.notes.begin(), f.notes.end());
  for (std::size_t i = 0; i < all.size(); ++i) o += (i ? "," : "") + json_str(all[i]);
  o += "]";
  if (explain) {
    o += ",\"candidates\":[";
    for (std::size_t i = 0; i < ex.candidates.size(); ++i) {
      const auto& c = ex.candidates[i];
      o += (i ? "," : "") + fmt::format("{{\"effect\":{},\"residual_after_rad\":{},\"dq_residual_after_a\":{},"
                                        "\"score\":{},\"bic_drop\":{},"
                                        "\"proposed\":{},\"reaches_floor\":{},\"reason\":{},\"params\":{{",
                                        json_str(c.effect), json_num(c.residual_after_rad),
                                        json_num(c.dq_residual_after), json_num(c.score),
                                        json_num(c.bic_drop), c.proposed, c.reaches_floor, json_str(c.reason));
      for (std::size_t j = 0; j < c.params.size(); ++j) {
        o += (j ? "," : "") + json_str(c.params[j].name) + ":{\"value\":" + json_num(c.params[j].value) +
             ",\"stderr\":" + json_num(c.params[j].std_error) + "}";
      }
      o += "}}";
    }
    o += "],\"where_it_fails\":[";
    for (std::size_t i = 0; i < ex.where_it_fails.size(); ++i) o += (i ? "," : "") + json_str(ex.where_it_fails[i]);
    o += "],\"missing_pair\":[";
    for (std::size_t i = 0; i < ex.missing_pair.size(); ++i) o += (i ? "," : "") + json_str(ex.missing_pair[i]);
    o += "],\"verdict\":" + json_str(to_string(ex.verdict)) + ",\"summary\":" + json_str(ex.summary);
  } else {
    o += std::string(",\"verdict\":") + (f.explained ? "\"explained\"" : "null");
  }
  return o + "}\n";
}

}  // namespace resolver
