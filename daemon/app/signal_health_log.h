// resolverd's side of the signal health monitor (daemon/core/health): takes the
// ADC full scale from the DBC, feeds the monitor, prints each fault once when it
// starts and once when it ends (with its sample time), and fills health_t.
#pragma once

#include <cstdint>
#include <ostream>
#include <vector>

#include <resolver/health_t.hpp>

#include "daemon/app/daemon_config.h"
#include "daemon/core/health/signal_health.h"
#include "daemon/decode/frame_decoder.h"

namespace resolver {

/// The health thresholds of `config` with full_scale and clip_margin taken from the
/// DBC's sin and cos signals (their declared range, else their raw range) unless
/// [health] full_scale sets it.
[[nodiscard]] SignalHealthConfig health_config_for(const DaemonConfig& config, const FrameDecoder& decoder);

class SignalHealthLog {
 public:
  /// Prints starts and ends to `out` with "resolverd: " in front.
  SignalHealthLog(const SignalHealthConfig& config, int p_r, double sample_rate_hz, std::ostream& out);

  void add(const Sample& s);
  void finish();
  /// A looped log's next pass begins (SignalHealthMonitor::new_pass).
  void new_pass() { monitor_.new_pass(); }
  void set_pole_pairs(int p_r) { monitor_.set_pole_pairs(p_r); }
  void set_sample_rate(double hz) { monitor_.set_sample_rate(hz); }
  void set_full_scale(double full_scale, double clip_margin) { monitor_.set_full_scale(full_scale, clip_margin); }
  /// New thresholds (config reload); everything counted so far stays.
  void set_config(const SignalHealthConfig& config) { monitor_.set_config(config); }
  /// atan2 of this sample's sin/cos is noise (amplitude lost): publish NaN.
  [[nodiscard]] bool sincos_lost(const Sample& s) const { return monitor_.sincos_lost(s); }
  /// Amplitude since the last call and every fault, into health_t.
  void fill(health_t& h);
  /// Everything so far, as resolver-model's summary has it.
  [[nodiscard]] SignalHealthSummary summary() const;
  [[nodiscard]] const SignalHealthMonitor& monitor() const { return monitor_; }

 private:
  void print(const SignalFaultEvent& e);

  SignalHealthMonitor monitor_;
  std::ostream& out_;
  std::vector<SignalFaultEvent> kept_;  ///< the first kKeptEvents, for summary()
  std::array<int, kSignalFaultCount> printed_{};
  bool have_t_ = false;
  double t_first_ = 0.0, t_last_ = 0.0;
};

}  // namespace resolver
