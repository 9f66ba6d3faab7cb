// resolverd — resolver bench daemon. Wiring only: parse options, load the
// config, build the pipeline with an LCM output, run a source, print a report.
#include <CLI/CLI.hpp>

#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>

#include "daemon/app/daemon_config.h"
#include "daemon/app/lcm_output.h"
#include "daemon/app/live_runner.h"
#include "daemon/app/pipeline.h"
#include "daemon/app/replay_runner.h"
#include "daemon/app/run_report.h"
#include "daemon/app/stop_flag.h"
#include "daemon/service/calibration_store.h"
#include "daemon/service/sd_notify.h"
#include "daemon/service/program_version.h"

namespace {

constexpr const char* kDescription = R"(resolverd: reads resolver sin/cos, R/D angle and phase currents from CAN,
estimates the resolver's amplitude imbalance (Hwang et al. 2009 integral method),
compensates the angle and publishes angle_t, dq_t, estimate_t and health_t on LCM.

Examples:
  # offline, as fast as possible, then print a report and exit
  resolverd --replay demo.log --once --fast --lcm 'file:///tmp/out.lcmlog?mode=w'
  # replay in the log's own timing, publishing on the default LCM multicast
  resolverd --replay demo.log
  # a Vector ASC log, or a scope export mapped by [input.csv] in the config; seconds 2..10 only
  resolverd --replay bench.asc --once --fast --from 2 --to 10
  resolverd --replay scope.csv --config scope.toml --once --fast
  # live from SocketCAN
  resolverd --can can0 --config /etc/resolverd/resolverd.toml

Watch the output with: resolver-echo --lcm 'udpm://239.255.76.67:7667?ttl=0' --count 10   (or lcm-spy, lcm-logger)
Channels (configurable in [channels]): RESOLVER_ANGLE, RESOLVER_DQ, RESOLVER_ESTIMATE,
RESOLVER_MODEL_FIT, RESOLVER_HEALTH. Signals: SIGTERM/SIGINT exit cleanly (with --replay,
after printing the report), SIGHUP reloads the config (a bad config keeps the old one).
)";

}  // namespace

static int run(int argc, char** argv) {
  using namespace resolver;
  CLI::App app{kDescription, "resolverd"};
  app.set_version_flag("--version", resolver::version_line("resolverd"));
  std::string config_path, replay_path, can_iface, report_path;
  std::optional<std::string> lcm_url;
  bool once = false, fast = false, quiet = false;
  app.add_option("--config", config_path, "TOML config file (see README; every key optional)")->check(CLI::ExistingFile);
  auto* replay = app.add_option("--replay", replay_path,
                                "replay a log file instead of reading CAN: candump -l, Vector ASC or a CSV/scope export")
                     ->check(CLI::ExistingFile);
  auto* can = app.add_option("--can", can_iface, "read live frames from this SocketCAN interface (can0, vcan0)");
  replay->excludes(can);
  app.add_flag("--once", once, "with --replay: stop at the end of the log (default: loop it)")->needs(replay);
  app.add_flag("--fast", fast, "with --replay: as fast as possible instead of the log's timing")->needs(replay);
  std::string format_name;
  SampleSlice slice;
  app.add_option("--format", format_name,
                 "with --replay: candump, asc (Vector ASC) or csv (scope export, [input.csv] in --config); "
                 "default: [input] format, else the extension (.asc, .csv/.txt, else candump)")
      ->check(CLI::IsMember({"candump", "asc", "csv"}))
      ->needs(replay);
  app.add_option("--from", slice.from_s, "with --replay: process samples from this time on [s, 0 = the log's first sample]")
      ->check(CLI::NonNegativeNumber)
      ->needs(replay);
  app.add_option("--to", slice.to_s, "with --replay: stop after this time [s, from the log's first sample]")
      ->check(CLI::NonNegativeNumber)
      ->needs(replay);
  app.add_option("--lcm", lcm_url,
                 "LCM URL, overrides the config (default: LCM's udpm multicast; "
                 "'file:///path.lcmlog?mode=w' writes a log file, 'memq://' stays in-process)");
  app.add_option("--report", report_path, "also write the end-of-run report as JSON to this file");
  app.add_flag("--quiet", quiet, "no progress lines on stderr");
  std::string state_dir;
  app.add_option("--state-dir", state_dir,
                 "directory for the persisted calibration (systemd: $STATE_DIRECTORY); loaded at start, "
                 "saved at exit when the estimate has converged");
  CLI11_PARSE(app, argc, argv);
  if (slice.to_s < slice.from_s) {
    std::cerr << "resolverd: --to " << slice.to_s << " s is before --from " << slice.from_s << " s\n";
    return 2;
  }
  if (replay_path.empty() && can_iface.empty()) {
    std::cerr << "resolverd: nothing to read: give --replay LOG or --can IFACE (see --help)\n";
    return 2;
  }

  DaemonConfig config;
  try {
    if (!config_path.empty()) config = load_daemon_config(config_path);
  } catch (const ConfigError& e) {
    std::cerr << "resolverd: " << e.what() << "\n";
    return 2;
  }
  if (lcm_url) config.lcm_url = *lcm_url;

  std::unique_ptr<LcmOutput> output;
  std::unique_ptr<Pipeline> pipeline;
  try {
    output = std::make_unique<LcmOutput>(config.lcm_url, config.channels);
    pipeline = std::make_unique<Pipeline>(config, *output, std::cerr, !can_iface.empty(), slice);
  } catch (const std::exception& e) {
    std::cerr << "resolverd: " << e.what() << "\n";
    return 2;
  }

  if (!state_dir.empty()) {
    const LoadResult loaded = load_calibration(state_dir);
    if (loaded.status == LoadResult::Status::kLoaded) {
      for (const auto& param : loaded.calibration->params) {
        if (param.name == "amplitude_imbalance.alpha") {
          pipeline->seed_alpha(param.value);
          std::cerr << "resolverd: compensating with the saved alpha = " << param.value << " from "
                    << calibration_path(state_dir) << " until this run's estimate converges\n";
        }
      }
    } else if (loaded.status == LoadResult::Status::kRejected) {
      std::cerr << "resolverd: " << loaded.problem << "\n";
    }
  }
  SdNotifier notifier = SdNotifier::from_environment();
  if (!notifier.last_error().empty()) std::cerr << "resolverd: " << notifier.last_error() << "\n";

  StopFlags flags;
  install_signal_handlers(flags);
  RunInfo info;
  try {
    if (!replay_path.empty()) {
      ReplayOptions ro;
      ro.path = replay_path;
      ro.format = log_format_from_name(format_name);
      ro.fast = fast;
      ro.once = once;
      ro.progress = !quiet;
      const ReplayResult rr = run_replay(ro, *pipeline, flags, std::cerr);
      info.source = replay_path;
      info.wall_seconds = rr.wall_seconds;
    } else {
      auto reload = [&]() {
        // SIGHUP: a new config replaces the pipeline only if it is valid.
        notifier.reloading();
        try {
          DaemonConfig fresh = config_path.empty() ? DaemonConfig{} : load_daemon_config(config_path);
          if (lcm_url) fresh.lcm_url = *lcm_url;
          auto rebuilt = std::make_unique<Pipeline>(fresh, *output, std::cerr, true);
          pipeline->finish();
          pipeline = std::move(rebuilt);
          config = fresh;
          std::cerr << "resolverd: config reloaded" << (config_path.empty() ? "" : " from " + config_path) << "\n";
        } catch (const std::exception& e) {
          std::cerr << "resolverd: reload failed, keeping the running config: " << e.what() << "\n";
        }
        notifier.ready();
      };
      const auto live_start = std::chrono::steady_clock::now();
      run_live(LiveOptions{can_iface, notifier.enabled() ? &notifier : nullptr, config.can.receive_buffer_bytes, config.can.wake_auto, config.can.wake_ids}, [&]() -> Pipeline& { return *pipeline; }, reload, flags, std::cerr);
      info.source = can_iface;
      info.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - live_start).count();
    }
  } catch (const ConfigError& e) {  // e.g. a CSV column map that does not fit the export
    std::cerr << "resolverd: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "resolverd: " << e.what() << "\n";
    return 1;
  }

  print_run_report(std::cout, *pipeline, info);
  const ModelEstimate model = pipeline->processor().estimate();
  if (!state_dir.empty() && model.converged) {
    Calibration cal;
    cal.p_r = pipeline->processor().config().p_r;
    cal.p = pipeline->processor().config().p;
    cal.method = model.method;
    cal.samples = model.samples;
    for (const ParamEstimate& prm : model.params) cal.params.push_back({prm.name, prm.value, prm.std_error});
    if (auto problem = save_calibration(state_dir, cal)) {
      std::cerr << "resolverd: " << *problem << "\n";
    } else {
      std::cerr << "resolverd: calibration saved to " << calibration_path(state_dir) << "\n";
    }
  }
  (void)output->flush();
  if (output->publish_failures() > 0) {
    std::cerr << "resolverd: " << output->publish_failures() << " LCM publish calls failed";
    if (!output->write_error().empty()) std::cerr << " (" << output->write_error() << ")";
    std::cerr << "\n";
  }
  if (!report_path.empty()) {
    std::ofstream out(report_path);
    out << run_report_json(*pipeline, info);
    if (!out) {
      std::cerr << "resolverd: cannot write report " << report_path << "\n";
      return 1;
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    // Last resort: every expected failure is reported where it happens.
    std::cerr << "resolverd: unexpected error: " << e.what() << "\n";
  } catch (...) {
    std::cerr << "resolverd: unexpected non-standard exception\n";
  }
  return 1;
}
