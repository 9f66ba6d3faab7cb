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

namespace {

/// Every property of a signal that changes what a frame decodes to.
std::string signal_key(const dbc::Signal* sig) {
  if (sig == nullptr) return "-";
  return fmt::format("{}@{}+{}{}{}*{:.17g}+{:.17g}:{}", sig->name, sig->start_bit, sig->length,
                     sig->order == dbc::ByteOrder::kLittleEndian ? "le" : "be", sig->is_signed ? "s" : "u", sig->factor,
                     sig->offset, static_cast<int>(sig->value_type));
}

}  // namespace

LayoutIdentity layout_identity(const DaemonConfig& config) {
  const auto decoder = make_frame_decoder(config);
  // What decodes a frame into a sample, and nothing else (comments, receivers, value
  // tables and the DBC's file name do not make another layout).
  std::string canonical = decoder->has_counter() ? "counter" : "no counter";
  for (const FrameDecoder::Slot& slot : decoder->slots()) {
    canonical += fmt::format("\n{} {:x}{} dlc {} counter {} crc {}", slot.message->name, slot.message->id,
                             slot.message->extended ? "x" : "", slot.message->dlc, signal_key(slot.counter),
                             signal_key(slot.crc));
    for (const FrameDecoder::RoleSignal& r : slot.roles) {
      canonical += fmt::format("\n  {} = {} to_unit {:.17g}{}", role_name(r.role), signal_key(r.signal), r.to_role_unit,
                               r.wrap ? " wrapped" : "");
    }
  }
  return {hex8(crc32_ieee(canonical)), describe_layout(config, *decoder)};
}

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
