#include "daemon/app/calibration_gate.h"

#include <fmt/format.h>

#include <ctime>
#include <fstream>
#include <sstream>

#include "daemon/core/health/signal_health.h"

namespace resolver {

CalibrationJudgement judge_calibration(const Pipeline& p) {
  std::vector<std::string> why;
  const ModelEstimate estimate = p.processor().estimate();
  if (!estimate.converged) {
    why.push_back(fmt::format("the estimate ({}) has not converged ({:.0f} revolutions used)", estimate.method,
                              estimate.revolutions));
  }
  if (const LiveModelFit* fit = p.model_fit(); fit != nullptr && fit->last().verdict == "unexplained") {
    // The reason starts with the verdict ("unexplained: the signals are faulty ...").
    const std::string& detail = fit->last().reason;
    why.push_back("the live model fit's last window: " + (detail.empty() ? std::string("unexplained") : detail));
  }
  const SignalHealthSummary health = p.signal_health().summary();
  FaultCounts counts{};
  for (std::size_t i = 0; i < kSignalFaultCount; ++i) counts[i] = health.faults[i].samples;
  const std::vector<std::string> faults = lasting_faults(counts, health.samples, kUntrustedFaultShare);
  for (const std::string& f : faults) why.push_back("signal fault " + f);
  CalibrationJudgement j;
  j.trusted = why.empty();
  for (std::size_t i = 0; i < why.size(); ++i) j.reason += (i ? "; " : "") + why[i];
  return j;
}

namespace {

std::string hex8(std::uint32_t v) { return fmt::format("{:08x}", v); }

std::optional<std::string> read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return std::nullopt;
  return text.str();
}

}  // namespace

std::string file_crc32(const std::string& path) {
  if (path.empty()) return "";
  const auto text = read_text(path);
  return text ? hex8(crc32_ieee(*text)) : std::string();
}

std::string utc_now(bool compact) {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, compact ? "%Y%m%dT%H%M%SZ" : "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace resolver
