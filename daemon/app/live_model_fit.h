// Live model discovery in resolverd (issue 4 "Live", docs/ARCHITECTURE.md §8): every window of
// `[model] window_revolutions` resolver revolutions the active model
// (`[model] effects`) is fitted to the window's samples and a model_fit_t is
// published, so an engineer watching the residual adds an effect (edit the
// config, SIGHUP) and sees it fall.
//
// The fit (model_discovery.h) takes tens of milliseconds, so it runs on a second
// thread while the pipeline keeps reading; its result is published from the
// pipeline's thread (the sink is not thread-safe), one window late.
//  - Replay (`realtime = false`): a finished window waits for the previous fit,
//    so every window is fitted, and a fit's result is published (its model compensates)
//    where the next window completes or the input ends, never at whichever sample a
//    poll found it done: the output is the same on every run, whatever the load.
//  - Live (`realtime = true`): the reader never waits; a window that completes
//    while the previous fit still runs is dropped and counted (windows_skipped).
// A window's fit starts where the last one converged (its model and the candidates it
// refitted exactly, settled: no other starts), which takes most of the passes off a
// window whose operating point has not moved. The first window that holds its speed at a
// new operating point (settled_at_a_new_operating_point) starts cold (the effects'
// defaults, every start), so a valley that moved with the speed is found again; so does
// one after a fit that did not converge, and at least every kColdEvery-th. The windows of
// the transition itself (a ramp, a reversal) stay warm: they hold the widest spread of
// speeds, and a loop model's every start there cost 4.4 s for one reversal window against
// 0.15 s for a steady one.
#pragma once

#include <cstdint>
#include <deque>
#include <future>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "daemon/app/daemon_config.h"
#include "daemon/app/output_sink.h"
#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/discovery/model_window.h"
#include "daemon/core/health/signal_health.h"

namespace resolver {

/// Builds the message for one window. `error` set: the fit could not run (too few
/// revolutions, no R/D angle...): verdict "insufficient_data" and NaN residuals.
[[nodiscard]] model_fit_t make_model_fit_message(const Explanation* ex, bool candidates,
                                                 const std::vector<std::string>& effects);

/// Whether mean speeds `last_speed` and `speed` [rad/s electrical, signed] are one
/// operating point: within 10 % of the faster, the same way.
[[nodiscard]] bool operating_point_held(double last_speed, double speed);
/// Whether a window at `speed` is the first steady one at a new operating point: moved from
/// `cold_speed` (the window where the fit last chose its valleys, from every start) and
/// held from `previous_speed` (the window before).
[[nodiscard]] bool settled_at_a_new_operating_point(double cold_speed, double previous_speed, double speed);

class LiveModelFit {
 public:
  struct Stamp {
    std::int64_t utime = 0;  ///< [us] of the window's last sample
    std::int64_t sample_index = 0;
    std::int16_t counter = 0;
  };
  struct Counters {
    std::int64_t windows_fitted = 0;
    std::int64_t windows_insufficient = 0;  ///< published with verdict insufficient_data
    std::int64_t windows_skipped = 0;       ///< live only: the previous fit was still running
  };

  /// `diagnostics` gets one line each time the reason a window cannot be fitted changes.
  LiveModelFit(const ModelFitOptions& options, OutputSink& sink, std::ostream& diagnostics, bool realtime);
  ~LiveModelFit();
  LiveModelFit(const LiveModelFit&) = delete;
  LiveModelFit& operator=(const LiveModelFit&) = delete;

  /// One joined sample (pole pairs as currently known) and the signal faults active
  /// at it (bit i: SignalFault i, signal_health.h). May publish the previous
  /// window's model_fit_t.
  void add(const Sample& sample, int p_r, int p, const Stamp& stamp, std::uint8_t active_faults = 0);
  /// End of input: waits for the running fit and publishes it. The open, partial
  /// window is fitted too when it covers at least two revolutions.
  void finish();
  [[nodiscard]] const Counters& counters() const { return counters_; }
  [[nodiscard]] double window_revolutions() const { return options_.window_revolutions; }
  /// A config reload replaced `previous` (finished) by this one: its window counts
  /// and last message carry on, so the run report covers the whole run.
  void continue_from(const LiveModelFit& previous) {
    counters_ = previous.counters_;
    last_ = previous.last_;
    taken_std_error_basis_ = previous.taken_std_error_basis_;
  }
  /// The last published message (verdict empty before the first window).
  [[nodiscard]] const model_fit_t& last() const { return last_; }

  /// The oldest model a window fitted that was not taken yet (nullopt: none new). The
  /// pipeline hands each to the processor, which compensates with it, and to the run's
  /// combined estimate: finish() may publish two (the window that was running and the
  /// tail), and neither may be lost (the run's estimate would then depend on how fast
  /// the fit ran).
  struct FittedModel {
    Model model;
    std::int64_t samples = 0;
    double revolutions = 0.0;
    std::string std_error_basis;  ///< std_error_basis(ModelFit): what its standard errors are from
  };
  [[nodiscard]] std::optional<FittedModel> take_model();
  /// std_error_basis of the last model take_model() handed out ("" before the first).
  [[nodiscard]] const std::string& taken_std_error_basis() const { return taken_std_error_basis_; }

 private:
  struct Result {
    model_fit_t message;
    std::string error;  ///< why the window could not be fitted ("" = fitted)
    std::optional<FittedModel> fitted;
    FitStartValues next_start;  ///< where the next window's fit starts (empty: cold)
  };
  void start(DiscoveryInput window, double speed, const Stamp& stamp, std::vector<std::string> untrusted);
  void publish_ready(bool wait);

  ModelFitOptions options_;
  OutputSink& sink_;
  std::ostream& diagnostics_;
  bool realtime_;
  ModelWindow window_;
  FaultCounts window_faults_{};     ///< samples of the open window under each fault
  std::int64_t window_samples_ = 0;
  /// The open window's lasting faults (DiscoveryOptions::untrusted_input); resets the counts.
  std::vector<std::string> take_window_faults();
  Stamp last_stamp_;
  std::future<Result> running_;
  std::string last_error_;
  model_fit_t last_{};
  std::uint32_t since_poll_ = 0;
  Counters counters_;
  std::string taken_std_error_basis_;
  std::deque<FittedModel> pending_models_;  ///< fitted, not taken yet, oldest first
  FitStartValues warm_start_;        ///< the last fitted window's (Result::next_start)
  double cold_speed_ = 0.0;          ///< [rad/s] mean speed of the last window started cold
  double previous_speed_ = 0.0;      ///< [rad/s] of the last window started (ModelWindow::mean_speed)
  std::int64_t warm_in_a_row_ = 0;   ///< windows started warm since the last cold one
};

}  // namespace resolver
