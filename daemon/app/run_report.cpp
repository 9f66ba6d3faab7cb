#include "daemon/app/run_report.h"

#include <fmt/format.h>

#include <cmath>

#include "daemon/core/angles.h"
#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/estimation/current_spike_gate.h"
#include "drivers/text/json_string.h"

namespace resolver {

namespace {

double ratio_db(double before, double after) {
  if (!(before > 0.0) || !(after > 0.0)) return std::nan("");
  return 20.0 * std::log10(after / before);
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return fmt::format("{:.17g}", v);  // round-trips a double
}

using text::json_string;  // drivers/text/json_string.h: the one JSON string writer

/// "completed by 0x102 (100.0 %)": the frame a live reader must wake up for.
void print_completing_frames(std::ostream& out, const CompletingFrames& c) {
  const std::int64_t total = c.total();
  if (total == 0) return;
  std::size_t top = 0;
  out << "  completed  by";
  for (std::size_t i = 0; i < c.size(); ++i) {
    const auto& [id, n] = c.at(i);
    out << fmt::format("{} 0x{:X}: {} ({:.1f} %)", i == 0 ? "" : ",", id, n,
                       100.0 * static_cast<double>(n) / static_cast<double>(total));
    if (n > c.at(top).second) top = i;
  }
  if (c.other() > 0) out << fmt::format(", other IDs: {}", c.other());
  out << fmt::format("; live, [can] wake_ids = [0x{:X}] wakes the daemon once per sample\n", c.at(top).first);
}

/// "signal     sin/cos amplitude ... ; faults: ..." and one line per fault seen.
void print_signal_health(std::ostream& out, const SignalHealthSummary& h, const SignalHealthConfig& c) {
  if (h.amplitude.n > 0) {
    out << fmt::format("  signal     sin/cos amplitude {:.1f} (min {:.1f}, max {:.1f}; full scale {:.0f})\n",
                       h.amplitude.mean(), h.amplitude.min, h.amplitude.max, c.full_scale);
  } else {
    out << "  signal     no sin/cos samples\n";
  }
  bool any = false;
  for (const auto& f : h.faults) {
    if (f.samples == 0) continue;
    any = true;
    out << fmt::format("  fault      {:<22} {:5.1f} % of the samples ({}, {} episode(s), {:.3f} .. {:.3f} s into the input{})\n",
                       fault_name(f.fault), 100.0 * f.share, f.samples, f.episodes, f.first_t - h.t_first,
                       f.last_t - h.t_first, f.active_at_end ? ", still at the end" : "");
  }
  if (!any && h.samples > 0) out << "  fault      none (loss/degradation of signal, tracking, clipping, stop, overspeed, outliers)\n";
  if (h.fault(SignalFault::kLossOfSignal).samples > 0) {
    out << "             loss_of_signal: no usable sin/cos (dead excitation or open channels); theta_sincos is NaN there\n";
  }
}

std::string signal_health_json(const SignalHealthSummary& h, const SignalHealthConfig& c) {
  std::string j = fmt::format("\"signal_health\":{{\"samples\":{},\"full_scale\":{},\"sincos_amplitude\":{},"
                              "\"sincos_amplitude_min\":{},\"sincos_amplitude_max\":{},\"faults\":{{",
                              h.samples, json_number(c.full_scale), json_number(h.amplitude.mean()),
                              json_number(h.amplitude.min), json_number(h.amplitude.max));
  for (std::size_t i = 0; i < h.faults.size(); ++i) {
    const auto& f = h.faults[i];
    // first_s / last_s: seconds after the first sample (null: never held).
    j += fmt::format("{}{}:{{\"samples\":{},\"share\":{},\"episodes\":{},\"first_s\":{},\"last_s\":{},"
                     "\"active_at_end\":{}}}",
                     i ? "," : "", json_string(fault_name(f.fault)), f.samples, json_number(f.share), f.episodes,
                     json_number(f.first_t - h.t_first), json_number(f.last_t - h.t_first),
                     f.active_at_end ? "true" : "false");
  }
  return j + "}}";
}

/// What the printed estimate's standard errors are from (hwang_integral's text line says
/// it itself; the JSON's std_error_basis has it for every method).
std::string estimate_std_error_basis(const Pipeline& p) {
  const ModelEstimate model = p.processor().estimate();
  if (p.processor().config().method == EstimatorMethod::kHwangIntegral) {
    return fmt::format("robust: revolution-to-revolution spread of {} revolutions (the whole run)",
                       p.processor().estimator().revolutions());
  }
  if (p.processor().config().method == EstimatorMethod::kModel && p.run_estimate().windows() > 1) {
    return p.run_estimate().basis();
  }
  if (p.processor().config().method == EstimatorMethod::kModel) {
    const LiveModelFit* mf = p.model_fit();
    const std::string basis = mf != nullptr ? mf->taken_std_error_basis() : std::string();
    return fmt::format("the last model window's fit alone ({:.0f} revolutions), not the whole run; {}", model.revolutions,
                       basis.empty() ? std::string("its basis not recorded (a model loaded, not fitted in this run)") : basis);
  }
  return fmt::format("formal: residual variance of the least squares over the {:.0f} revolutions above", model.revolutions);
}

/// Why nothing was published compensated, naming the key that changes it.
std::string not_compensated_reason(const Pipeline& p) {
  const ProcessorConfig& pc = p.processor().config();
  if (!pc.compensate) return "compensation disabled ([compensation] enabled = false)";
  if (pc.method != EstimatorMethod::kModel) {
    return fmt::format("the {} estimate never converged", p.processor().estimate().method);
  }
  const LiveModelFit* mf = p.model_fit();
  if (mf == nullptr) return "[model] enabled = false: method \"model\" compensates with the live model fit";
  // The fit of the last, partial window comes at the end of the input, when no sample
  // is left to compensate: a log shorter than one window is never compensated.
  return fmt::format("no model window was fitted before the input ended (the first needs [model] "
                     "window_revolutions = {:g} resolver revolutions, the input turned {:.0f}): set "
                     "window_revolutions lower (>= 2), replay without --once, or use [estimator] method = "
                     "\"sincos_least_squares\" (converges within a revolution)",
                     mf->window_revolutions(), p.processor().estimate().revolutions);
}

}  // namespace

namespace {

/// Frames, samples, the slice, rejects and interfaces.
void print_intake(std::ostream& out, const Pipeline& p, const RunInfo& info) {
  const IntakeStats& st = p.intake().stats();
  out << fmt::format("resolverd report: {}\n", info.source);
  out << fmt::format("  frames     {} seen, {} decoded, {} CAN error frames; {:.0f} frames/s processed\n",
                     st.frames_seen, st.frames_decoded, st.bus_errors,
                     info.wall_seconds > 0 ? static_cast<double>(st.frames_seen) / info.wall_seconds : 0.0);
  out << fmt::format("  samples    {} complete, {} incomplete\n", st.samples_complete, st.samples_incomplete);
  if (const SampleSlice& sl = p.stream().slice(); sl.limited()) {
    out << fmt::format("  slice      --from {} s --to {} s: {} samples used, {} read outside it\n", sl.from_s, sl.to_s,
                       p.samples(), p.stream().samples_outside_slice());
  }
  print_completing_frames(out, p.completing_frames());
  if (p.intake().rejects().all().empty()) {
    out << "  rejected   none\n";
  } else {
    out << "  rejected  ";
    for (const auto& [reason, n] : p.intake().rejects().all()) out << fmt::format(" {}={}", reason, n);
    out << "\n";
  }
  if (const std::string note = p.intake().interface_note(); !note.empty()) out << "  interfaces " << note << "\n";
}

/// The active method's final estimate with what its errors are from.
void print_estimate(std::ostream& out, const Pipeline& p) {
  const HwangIntegralEstimator& est = p.processor().estimator();
  const ProcessorConfig& pc = p.processor().config();
  const ModelEstimate model = p.processor().estimate();
  if (pc.method == EstimatorMethod::kHwangIntegral) {
    out << fmt::format("  estimate   hwang_integral: alpha = {:.6f} +- {:.2e} (std. error; spread {:.2e} over {} revolutions) {}\n",
                       est.alpha(), est.alpha_stderr(), est.alpha_spread(), est.revolutions(),
                       est.converged() ? "converged" : "NOT converged");
    out << fmt::format("             revolutions rejected: speed not constant {}, too few samples {}, too slow {}, samples lost {}\n",
                       est.rejected(HwangRejection::kSpeedNotConstant), est.rejected(HwangRejection::kTooFewSamples),
                       est.rejected(HwangRejection::kTooSlow), est.rejected(HwangRejection::kGap));
  } else {
    out << fmt::format("  estimate   {}: {} over {:.0f} revolutions{}\n", model.method,
                       model.converged ? "converged" : "NOT converged", model.revolutions,
                       model.params.empty() ? " (no fit: missing signals? sincos needs sin/cos, fourier a reference)" : "");
    for (const ModelParameter& prm : model.params) {
      out << fmt::format("             {:<28} = {:+.6e} +- {:.2e}\n", prm.name, prm.value, prm.std_error);
    }
    if (!model.params.empty()) out << "             +- standard error: " << estimate_std_error_basis(p) << "\n";
  }
}

/// The samples, and the position error against the reference, raw and compensated.
void print_position(std::ostream& out, const Pipeline& p) {
  const RunSummary& s = p.summary();
  const ProcessorConfig& pc = p.processor().config();
  out << fmt::format("  samples    {} with an angle over {:.3f} s, {} moving, {} at standstill, {} with a reference\n",
                     s.samples, s.t_last - s.t_first, s.moving, s.samples - s.moving, s.with_reference);
  if (s.raw_all.stats.n > 1) {
    auto line = [&](const char* what, const ErrorStats& e) {
      out << fmt::format("             {:<40} {:>8} samples, {:.3f}-{:.3f} s: RMS {:.3f} arcmin (mean {:+.3f}, about the "
                         "mean {:.3f})\n",
                         what, e.stats.n, e.t_first - s.t_first, e.t_last - s.t_first, rad_to_arcmin(e.rms()),
                         rad_to_arcmin(e.stats.mean), rad_to_arcmin(e.stats.stddev()));
    };
    out << fmt::format("  position   error vs reference [arcmin of the resolver angle; / {} for mechanical]:\n", pc.p_r);
    line("raw, every sample with a reference", s.raw_all);
    line("raw, moving samples", s.raw_moving);
    if (s.compared_comp.stats.n > 1) {
      line("raw, moving, while compensated", s.compared_raw);
      line("compensated, the same samples", s.compared_comp);
      out << fmt::format("             compensation: RMS {:.3f} -> {:.3f} arcmin ({:+.1f} dB) over the moving samples "
                         "since it started\n",
                         rad_to_arcmin(s.compared_raw.rms()), rad_to_arcmin(s.compared_comp.rms()),
                         ratio_db(s.compared_raw.rms(), s.compared_comp.rms()));
    } else {
      out << "             not compensated: " << not_compensated_reason(p) << "\n";
    }
  } else {
    out << "  position   no reference angle in the log: error vs reference not measured\n";
    if (s.compensated > 0) {
      out << fmt::format("             compensated from {:.3f} s: {} of {} samples published compensated\n",
                         s.t_compensation_start - s.t_first, s.compensated, s.samples);
    } else {
      out << "             not compensated: " << not_compensated_reason(p) << "\n";
    }
  }
}

/// The dq ripple at 1x, 2x, 6x theta_e.
void print_ripple(std::ostream& out, const RunSummary& s) {
  if (s.have_ripple) {
    const RippleSet& r = s.ripple;
    for (std::size_t k = 0; k < 3; ++k) {
      out << fmt::format("  dq ripple  {}x theta_e: i_d raw {:.2f} mA -> comp {:.2f} mA ({:+.1f} dB); i_q raw {:.2f} -> comp {:.2f} mA",
                         kRippleOrders[k], 1e3 * r.raw.d[k], 1e3 * r.comp.d[k], ratio_db(r.raw.d[k], r.comp.d[k]),
                         1e3 * r.raw.q[k], 1e3 * r.comp.q[k]);
      if (r.ref_valid) out << fmt::format("; with reference angle i_d {:.2f} mA", 1e3 * r.ref.d[k]);
      out << "\n";
    }
  } else {
    out << "  dq ripple  not measured (no phase currents, or no converged estimate)\n";
  }
  if (s.current_spikes > 0) {
    out << fmt::format("  dq ripple  {} phase-current sample(s) were spikes (off the line of their neighbours by over "
                       "{:g} robust sigmas): the ripple took the line's value for them\n",
                       s.current_spikes, CurrentSpikeGate::kThreshold);
  }
}

/// The live model fit, reloads, the calibration and the latency.
void print_run_record(std::ostream& out, const Pipeline& p, const RunInfo& info) {
  if (const LiveModelFit* mf = p.model_fit()) {
    const auto& c = mf->counters();
    const model_fit_t& last = mf->last();
    out << fmt::format("  model fit  {} windows fitted, {} insufficient, {} skipped; last window: verdict {}", c.windows_fitted,
                       c.windows_insufficient, c.windows_skipped, last.verdict.empty() ? "(none)" : last.verdict);
    if (!last.verdict.empty() && std::isfinite(last.residual_rms_rad)) {
      if (last.verdict == "missing_effect" && !last.candidate_effect.empty()) {
        out << " (add " << last.candidate_effect.front() << ")";
      }
      out << fmt::format("; position-error residual {:.3g} rad = {:.2f}x floor", last.residual_rms_rad,
                         last.residual_rms_rad / last.noise_floor_rad);
    }
    out << "\n";
  }
  if (!p.reloads().empty()) {
    out << fmt::format("  reloads    {} (SIGHUP), the report covers the whole run:", p.reloads().size());
    for (const Pipeline::Reload& r : p.reloads()) {
      out << fmt::format(" {:.3f} s (sample {}, {})", r.t_s, r.sample_index,
                         r.estimate_kept ? "estimate kept" : "estimation restarted");
    }
    out << "\n";
  }
  if (info.calibration.saved) {
    out << fmt::format("  calibration saved to {}\n", info.calibration.path);
  } else if (!info.calibration.path.empty()) {
    out << fmt::format("  calibration not saved to {}: {}\n", info.calibration.path, info.calibration.reason);
  }
  const LatencyHistogram& lat = p.latency_total();
  out << fmt::format("  latency    frame read -> publish return: p50 {:.0f} us, p99 {:.0f} us, max {:.0f} us ({} frames timed)\n",
                     lat.percentile(0.5), lat.percentile(0.99), lat.max(), lat.count());
}

}  // namespace

void print_run_report(std::ostream& out, const Pipeline& p, const RunInfo& info) {
  print_intake(out, p, info);
  const ProcessorConfig& pc = p.processor().config();
  out << fmt::format("  bench      p_r={} p={}\n", pc.p_r, pc.p);
  print_signal_health(out, p.signal_health().summary(), p.signal_health().monitor().config());
  print_estimate(out, p);
  print_position(out, p);
  print_ripple(out, p.summary());
  print_run_record(out, p, info);
}

std::string run_report_json(const Pipeline& p, const RunInfo& info) {
  const IntakeStats& st = p.intake().stats();
  const HwangIntegralEstimator& est = p.processor().estimator();
  const RunSummary& s = p.summary();
  std::string j = "{";
  j += fmt::format("\"source\":{},\"wall_seconds\":{},", json_string(info.source), json_number(info.wall_seconds));
  j += fmt::format("\"frames_seen\":{},\"frames_decoded\":{},\"bus_errors\":{},\"samples_complete\":{},\"samples_incomplete\":{},",
                   st.frames_seen, st.frames_decoded, st.bus_errors, st.samples_complete, st.samples_incomplete);
  j += fmt::format("\"samples_used\":{},\"samples_outside_slice\":{},", p.samples(), p.stream().samples_outside_slice());
  j += "\"rejects\":{";
  bool first = true;
  for (const auto& [reason, n] : p.intake().rejects().all()) {
    j += fmt::format("{}{}:{}", first ? "" : ",", json_string(reason), n);
    first = false;
  }
  j += "},\"interfaces\":[";
  for (std::size_t i = 0; i < p.intake().interfaces().size(); ++i) {
    const InterfaceFrames& f = p.intake().interfaces()[i];
    j += fmt::format("{}{{\"name\":{},\"frames\":{},\"left_out\":{},\"read\":{}}}", i ? "," : "", json_string(f.name),
                     f.frames, f.left_out, f.read ? "true" : "false");
  }
  j += "],";
  j += fmt::format("\"p_r\":{},\"p\":{},", p.processor().config().p_r, p.processor().config().p);
  const ModelEstimate model = p.processor().estimate();
  double alpha = est.alpha(), alpha_se = est.alpha_stderr();
  const std::string alpha_name = amplitude_imbalance_alpha_name();
  for (const ModelParameter& prm : model.params) {
    if (prm.name == alpha_name) {
      alpha = prm.value;
      alpha_se = prm.std_error;
    }
  }
  j += fmt::format("\"method\":{},\"alpha\":{},\"alpha_stderr\":{},\"alpha_spread\":{},\"revolutions\":{},\"converged\":{},",
                   json_string(model.method), json_number(alpha), json_number(alpha_se), json_number(est.alpha_spread()),
                   json_number(model.revolutions), model.converged ? "true" : "false");
  j += "\"params\":{";
  for (std::size_t i = 0; i < model.params.size(); ++i) {
    j += fmt::format("{}{}:{{\"value\":{},\"stderr\":{}}}", i ? "," : "", json_string(model.params[i].name),
                     json_number(model.params[i].value), json_number(model.params[i].std_error));
  }
  j += "},\"std_error_basis\":" + json_string(estimate_std_error_basis(p)) + ",";
  auto stats_json = [&](const ErrorStats& e) {
    return fmt::format("{{\"samples\":{},\"t_first_s\":{},\"t_last_s\":{},\"rms_rad\":{},\"mean_rad\":{},"
                       "\"std_rad\":{}}}",
                       e.stats.n, json_number(e.t_first - s.t_first), json_number(e.t_last - s.t_first),
                       json_number(e.rms()), json_number(e.stats.value_or_nan()), json_number(e.stats.stddev()));
  };
  j += fmt::format("\"samples_with_angle\":{},\"samples_moving\":{},\"samples_with_reference\":{},\"span_s\":{},",
                   s.samples, s.moving, s.with_reference, json_number(s.t_last - s.t_first));
  j += "\"position_error\":{\"units\":\"rad, resolver electrical\",\"raw_all\":" + stats_json(s.raw_all) +
       ",\"raw_moving\":" + stats_json(s.raw_moving) + ",\"compensated_moving\":" + stats_json(s.compared_comp) +
       ",\"raw_same_samples\":" + stats_json(s.compared_raw) + "},";
  // The compensated figure against the raw one over the same samples (RMS including the mean).
  j += fmt::format("\"eps_rms_raw_rad\":{},\"eps_rms_comp_rad\":{},", json_number(s.compared_raw.rms()),
                   json_number(s.compared_comp.rms()));
  j += fmt::format("\"compensation\":{{\"samples\":{},\"started_s\":{},\"reason\":{}}},", s.compensated,
                   json_number(s.compensated > 0 ? s.t_compensation_start - s.t_first : std::nan("")),
                   s.compensated > 0 ? "null" : json_string(not_compensated_reason(p)));
  const RippleSet& r = s.ripple;
  auto arr = [&s](const std::array<double, 3>& a, bool valid) {
    if (!s.have_ripple || !valid) return std::string("null");
    return fmt::format("[{},{},{}]", json_number(a[0]), json_number(a[1]), json_number(a[2]));
  };
  j += "\"ripple_orders\":[1,2,6],";
  j += "\"i_d_ripple_raw\":" + arr(r.raw.d, r.raw_valid) + ",\"i_d_ripple_comp\":" + arr(r.comp.d, r.comp_valid) +
       ",\"i_d_ripple_ref\":" + arr(r.ref.d, r.ref_valid) + ",";
  j += "\"i_q_ripple_raw\":" + arr(r.raw.q, r.raw_valid) + ",\"i_q_ripple_comp\":" + arr(r.comp.q, r.comp_valid) +
       ",\"i_q_ripple_ref\":" + arr(r.ref.q, r.ref_valid);
  j += fmt::format(",\"ripple_current_spikes\":{}", s.current_spikes);
  j += "," + signal_health_json(p.signal_health().summary(), p.signal_health().monitor().config());
  if (const LiveModelFit* mf = p.model_fit()) {
    const auto& c = mf->counters();
    const model_fit_t& last = mf->last();
    j += fmt::format(",\"model_fit\":{{\"windows_fitted\":{},\"windows_insufficient\":{},\"windows_skipped\":{},"
                     "\"last_verdict\":{},\"last_residual_rms_rad\":{},\"last_noise_floor_rad\":{},\"last_best_candidate\":{}}}",
                     c.windows_fitted, c.windows_insufficient, c.windows_skipped, json_string(last.verdict),
                     json_number(last.residual_rms_rad), json_number(last.noise_floor_rad),
                     json_string(last.candidate_effect.empty() ? std::string() : last.candidate_effect.front()));
  }
  // Config reloads (SIGHUP): when each happened, in sample time from the first sample and bench time.
  j += fmt::format(",\"reload_count\":{},\"reloads\":[", p.reloads().size());
  for (std::size_t i = 0; i < p.reloads().size(); ++i) {
    const Pipeline::Reload& rl = p.reloads()[i];
    j += fmt::format("{}{{\"t_s\":{},\"sample_index\":{},\"utime\":{},\"estimate_kept\":{},\"what\":{}}}", i ? "," : "",
                     json_number(rl.t_s), rl.sample_index, rl.utime, rl.estimate_kept ? "true" : "false",
                     json_string(rl.what));
  }
  j += "]";
  j += fmt::format(",\"calibration\":{{\"path\":{},\"saved\":{},\"reason\":{}}}", json_string(info.calibration.path),
                   info.calibration.saved ? "true" : "false",
                   info.calibration.saved ? "null" : json_string(info.calibration.reason));
  j += "}\n";
  return j;
}

}  // namespace resolver
