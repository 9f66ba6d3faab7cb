#include "tools/sim/sim_truth.h"

#include <fmt/format.h>

#include "daemon/core/effects/chain_values.h"
#include "drivers/text/json_string.h"

namespace resolver {

namespace {
using text::json_string;  // drivers/text/json_string.h: the one JSON string writer

// fmt's "{}" is the shortest round-trip form of a double, which is valid JSON for finite values.
std::string parameters_json(const std::vector<std::pair<std::string_view, double>>& params) {
  std::string out = "{";
  for (std::size_t i = 0; i < params.size(); ++i) {
    out += fmt::format("{}{}: {}", i == 0 ? "" : ", ", json_string(params[i].first), params[i].second);
  }
  return out + "}";
}
}  // namespace

std::string sim_truth_json(const SimConfig& c, std::uint64_t total_samples, const std::string& log_path) {
  std::string out = "{\n";
  out += fmt::format("  \"generator\": \"resolver-sim\",\n  \"log\": {},\n", json_string(log_path));
  out += fmt::format("  \"samples\": {},\n  \"start_time_us\": {},\n  \"sample_rate_hz\": {},\n", total_samples,
                     c.start_time_us, c.sample_rate_hz);
  out += fmt::format("  \"p_r\": {},\n  \"p\": {},\n  \"rd_bits\": {},\n  \"amplitude_counts\": {},\n", c.p_r, c.p,
                     c.rd_bits, c.amplitude_counts);
  out += fmt::format("  \"i_d_cmd\": {},\n  \"i_q_cmd\": {},\n  \"reference\": {},\n  \"seed\": {},\n", c.i_d_cmd,
                     c.i_q_cmd, c.reference ? "true" : "false", c.seed);
  out += fmt::format("  \"theta_m0\": {},\n  \"iface\": {},\n  \"profile\": [", c.theta_m0, json_string(c.iface));
  for (std::size_t i = 0; i < c.profile.size(); ++i) {
    const SpeedSegment& s = c.profile[i];
    out += fmt::format("{}{{\"duration_s\": {}, \"rpm_start\": {}, \"rpm_end\": {}}}", i == 0 ? "" : ", ",
                       s.duration_s, s.rpm_start, s.rpm_end);
  }
  out += "],\n  \"effects\": {";
  const auto active = c.chain.active_effects();
  for (std::size_t i = 0; i < active.size(); ++i) {
    out += fmt::format("{}\n    {}: {}", i == 0 ? "" : ",", json_string(active[i].effect->name()),
                       parameters_json(active[i].parameters));
  }
  out += active.empty() ? "},\n" : "\n  },\n";
  out += "  \"chain\": {";
  bool first = true;
  for (const Effect* e : effect_registry()) {
    std::vector<std::pair<std::string_view, double>> params;
    const Values v = c.chain.of(*e);
    for (std::size_t i = 0; i < e->params().size(); ++i) params.emplace_back(e->params()[i].name, v[i]);
    out += fmt::format("{}\n    {}: {}", first ? "" : ",", json_string(e->name()), parameters_json(params));
    first = false;
  }
  out += "\n  }\n}\n";
  return out;
}

}  // namespace resolver
