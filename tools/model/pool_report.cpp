#include "tools/model/pool_report.h"

#include <cmath>

#include <fmt/format.h>

#include "tools/model/json_text.h"

namespace resolver {

namespace {

/// "1.23e-05 (1.1x floor)" or "n/a" for a signal the log lacks.
std::string against_floor(double rms, const ModelFit& f, const char* signal) {
  if (!std::isfinite(rms)) return "n/a";
  for (const SignalResidual& s : f.signals) {
    if (s.signal == signal && s.floor > 0.0) return fmt::format("{:.3g} ({:.2f}x)", rms, rms / s.floor);
  }
  return fmt::format("{:.3g}", rms);
}

std::string json_param(const ModelParameter& p) {
  return fmt::format("{{\"name\":{},\"value\":{},\"stderr\":{}}}", json::str(p.name), json::num(p.value),
                     json::num(p.std_error));
}

}  // namespace

std::string format_pool_text(const std::vector<std::string>& names, const ModelFit& f, const LogComparison& logs) {
  std::string o = fmt::format(
      "\npooled over {} logs: the parameters above are shared; each log has its own reference zero, envelope "
      "amplitude and operating point (nuisance.*[log]). Each log's residual in the pooled fit (x its pooled floor):\n",
      names.size());
  o += fmt::format("  {:<32} {:>9}  {:<20} {:<20} {}\n", "log", "rows", "position_error", "sin_cos", "i_dq");
  for (const PartResidual& r : f.parts) {
    o += fmt::format("  {:<32} {:>9}  {:<20} {:<20} {}\n", r.name, r.rows, against_floor(r.position_rms, f, "position_error"),
                     against_floor(r.sincos_rms, f, "sin_cos"), against_floor(r.dq_rms, f, "i_dq"));
  }
  o += fmt::format("\neach log fitted alone against the other logs' own fits (z = difference / its standard error; "
                   "beyond {:g} the log disagrees):\n",
                   kPoolDisagreementZ);
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!logs.alone_failed[i].empty()) o += fmt::format("  {}: its own fit failed: {}\n", names[i], logs.alone_failed[i]);
  }
  int shown = 0;
  for (const PoolDisagreement& d : logs.comparisons) {
    const bool disagrees = std::abs(d.z) > kPoolDisagreementZ;
    if (!disagrees && shown >= 3) break;  // the agreeing ones: the closest calls only
    // The relative change beside z: a real but tiny change (0.1 %) reads apart from a large one.
    const std::string change = d.others != 0.0 ? fmt::format(" ({:+.2g} %)", 100.0 * (d.value - d.others) / std::abs(d.others)) : "";
    o += fmt::format("  {:<32} {:<34} {:>12.6g} +- {:<8.2g} others {:>12.6g} +- {:<8.2g} z = {:>6.1f}{}{}\n", d.log,
                     d.parameter, d.value, d.std_error, d.others, d.others_std_error, d.z, change,
                     disagrees ? "  DISAGREES" : "");
    ++shown;
  }
  const auto beyond = std::count_if(logs.comparisons.begin(), logs.comparisons.end(),
                                    [](const PoolDisagreement& d) { return std::abs(d.z) > kPoolDisagreementZ; });
  o += beyond == 0 ? fmt::format("  every log agrees with the others ({} comparisons within {:g} standard errors)\n",
                                 logs.comparisons.size(), kPoolDisagreementZ)
                   : fmt::format("  {} of {} comparisons disagree\n", beyond, logs.comparisons.size());
  return o;
}

std::string format_pool_json(const std::vector<std::string>& names, const ModelFit& f, const LogComparison& logs) {
  std::string per_log;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const PartResidual none{names[i], 0, std::nan(""), std::nan(""), std::nan("")};
    const PartResidual* r = i < f.parts.size() ? &f.parts[i] : &none;
    std::string alone, nuisance;
    for (const ModelParameter& q : logs.alone[i].params) alone += (alone.empty() ? "" : ",") + json_param(q);
    // This log's own constants ("nuisance.rd_constant[LOG]": its reference's zero ...), by their plain names.
    const std::string suffix = "[" + names[i] + "]";
    for (const ModelParameter& q : f.nuisance) {
      if (!q.name.ends_with(suffix)) continue;
      nuisance += fmt::format("{}{}:{}", nuisance.empty() ? "" : ",", json::str(q.name.substr(0, q.name.size() - suffix.size())),
                              json::num(q.value));
    }
    per_log += fmt::format("{}{{\"log\":{},\"rows\":{},\"position_rms_rad\":{},\"sincos_rms\":{},\"dq_rms_a\":{},"
                        "\"nuisance\":{{{}}},\"alone\":{{\"params\":[{}],\"error\":{}}}}}",
                        i ? "," : "", json::str(names[i]), r->rows, json::num(r->position_rms),
                        json::num(r->sincos_rms), json::num(r->dq_rms), nuisance, alone,
                        logs.alone_failed[i].empty() ? "null" : json::str(logs.alone_failed[i]));
  }
  std::string cmp;
  for (const PoolDisagreement& d : logs.comparisons) {
    cmp += fmt::format("{}{{\"log\":{},\"parameter\":{},\"value\":{},\"stderr\":{},\"others\":{},\"others_stderr\":{},"
                       "\"pooled\":{},\"z\":{},\"disagrees\":{}}}",
                       cmp.empty() ? "" : ",", json::str(d.log), json::str(d.parameter), json::num(d.value),
                       json::num(d.std_error), json::num(d.others), json::num(d.others_std_error), json::num(d.pooled),
                       json::num(d.z, 4),
                       std::abs(d.z) > kPoolDisagreementZ ? "true" : "false");
  }
  return fmt::format(",\"pool\":{{\"z_limit\":{},\"logs\":[{}],\"comparisons\":[{}]}}", json::num(kPoolDisagreementZ),
                     per_log, cmp);
}

}  // namespace resolver
