#include "daemon/app/signal_health_log.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace resolver {

namespace {

/// Starts of one fault printed in full; after that they are only counted (a fault
/// flapping at a threshold must not flood the journal; health_t has every count).
constexpr int kPrintedStarts = 10;
/// Events kept for the run report's summary.
constexpr std::size_t kKeptEvents = 1000;

/// [signal units] the largest magnitude a signal can carry: its DBC range, or the
/// range its raw bits span when the DBC declares none ([0|0]).
double signal_full_scale(const dbc::Signal& sig) {
  double lo = sig.minimum, hi = sig.maximum;
  if (!(hi > lo)) {
    const double bits = std::ldexp(1.0, static_cast<int>(std::min<std::uint32_t>(sig.length, 63)));
    const double raw_lo = sig.is_signed ? -bits / 2.0 : 0.0;
    const double raw_hi = sig.is_signed ? bits / 2.0 - 1.0 : bits - 1.0;
    lo = std::min(raw_lo * sig.factor, raw_hi * sig.factor) + sig.offset;
    hi = std::max(raw_lo * sig.factor, raw_hi * sig.factor) + sig.offset;
  }
  // A symmetric ADC code range (-32768..32767) clips at the smaller magnitude.
  return std::min(std::abs(lo), std::abs(hi));
}

}  // namespace

SignalHealthConfig health_config_for(const DaemonConfig& config, const FrameDecoder& decoder) {
  SignalHealthConfig h = config.health;
  if (config.health_full_scale_set) return h;
  double full_scale = 0.0, lsb = 0.0;
  for (const auto& slot : decoder.slots()) {
    for (const auto& r : slot.roles) {
      if (r.role != Role::kSin && r.role != Role::kCos) continue;
      const double fs = signal_full_scale(*r.signal);
      full_scale = full_scale > 0.0 ? std::min(full_scale, fs) : fs;
      lsb = std::max(lsb, std::abs(r.signal->factor));
    }
  }
  if (full_scale > 0.0) {
    h.full_scale = full_scale;
    h.clip_margin = 0.5 * lsb;  // half a code: a sample at the last code is clipped
  }
  return h;
}

SignalHealthLog::SignalHealthLog(const SignalHealthConfig& config, int p_r, double sample_rate_hz, std::ostream& out)
    : monitor_(config, p_r, sample_rate_hz), out_(out) {}

void SignalHealthLog::print(const SignalFaultEvent& e) {
  if (kept_.size() < kKeptEvents) kept_.push_back(e);
  const auto i = static_cast<std::size_t>(e.fault);
  const std::string_view name = fault_name(e.fault);
  if (e.started) {
    const int n = ++printed_[i];
    if (n <= kPrintedStarts) {
      out_ << fmt::format("resolverd: signal fault {} started {:.3f} s into the input (sample {}): {}\n", name,
                          e.t - t_first_, e.index, e.detail);
    } else if (n == kPrintedStarts + 1) {
      out_ << fmt::format("resolverd: signal fault {} keeps coming back; further starts and ends are counted "
                          "(health_t fault_count, the report), not printed\n",
                          name);
    }
  } else if (printed_[i] <= kPrintedStarts) {
    const SignalFaultState& st = monitor_.fault(e.fault);
    out_ << fmt::format("resolverd: signal fault {} ended {:.3f} s into the input (sample {}); {} sample(s) so far\n",
                        name, e.t - t_first_, e.index, st.samples);
  }
}

void SignalHealthLog::add(const Sample& s) {
  if (!have_t_) t_first_ = s.t;
  have_t_ = true;
  t_last_ = s.t;
  monitor_.add(s);
  for (const SignalFaultEvent& e : monitor_.take_events()) print(e);
}

void SignalHealthLog::finish() {
  monitor_.finish();
  for (const SignalFaultEvent& e : monitor_.take_events()) print(e);
}

void SignalHealthLog::fill(health_t& h) {
  const AmplitudeStats a = monitor_.take_amplitude_window();
  h.sincos_amplitude = a.mean();
  h.sincos_amplitude_min = a.min;
  h.sincos_amplitude_max = a.max;
  h.fault_name.clear();
  h.fault_count.clear();
  h.fault_active.clear();
  for (std::size_t i = 0; i < kSignalFaultCount; ++i) {
    const SignalFaultState& st = monitor_.faults()[i];
    h.fault_name.emplace_back(fault_name(static_cast<SignalFault>(i)));
    h.fault_count.push_back(st.samples);
    h.fault_active.push_back(st.active ? 1 : 0);
  }
  h.num_faults = static_cast<std::int32_t>(kSignalFaultCount);
}

SignalHealthSummary SignalHealthLog::summary() const { return summarize(monitor_, kept_, t_first_, t_last_); }

}  // namespace resolver
