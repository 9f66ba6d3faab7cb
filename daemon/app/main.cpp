// resolverd — resolver bench daemon. Wiring only: parse options, load the
// config, build the pipeline with an LCM output, run a source, print a report.
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <string_view>

#include "daemon/app/calibration_gate.h"
#include "daemon/app/daemon_config.h"
#include "daemon/app/exit_codes.h"
#include "daemon/app/lcm_output.h"
#include "daemon/app/live_runner.h"
#include "daemon/app/pipeline.h"
#include "daemon/app/replay_runner.h"
#include "daemon/app/run_report.h"
#include "daemon/app/stop_flag.h"
#include "daemon/service/calibration_store.h"
#include "daemon/service/state_dir_lock.h"
#include "daemon/service/table_file.h"
#include "daemon/service/sd_notify.h"
#include "daemon/service/program_version.h"

namespace {

constexpr const char* kDescription = R"(resolverd: reads resolver sin/cos, R/D angle and phase currents from CAN,
fits the active effect model live ([model] effects, default amplitude_imbalance; by
default the estimator too: [estimator] method = "model"; the seed's Hwang et al. 2009
integral method is "hwang_integral"), compensates the angle by inverting the model and
publishes angle_t, dq_t, estimate_t, model_fit_t and health_t (with the signal faults:
loss of signal, degradation, loss of tracking, clipping, stop, overspeed, outliers) on LCM.

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
  # four times the log's speed: lcm-logger keeps up where --fast would make it drop
  resolverd --replay demo.log --once --rate 4

Watch the output with: resolver-echo --lcm 'udpm://239.255.76.67:7667?ttl=0' --count 10   (or lcm-spy, lcm-logger)
Channels (configurable in [channels]): RESOLVER_ANGLE, RESOLVER_DQ, RESOLVER_ESTIMATE,
RESOLVER_MODEL_FIT, RESOLVER_HEALTH. A file:///PATH?mode=w log is stamped with bench time
(each message's utime), so lcm-logplayer plays it at the bench's speed whatever --fast did.
On udpm, --fast publishes as fast as the CPU allows and listeners (lcm-logger, lcm-spy) drop
what their socket buffers cannot hold: use --rate X, or write a file:// log.
Signals: SIGTERM/SIGINT end it within a second on any input (the report is printed);
SIGHUP reloads the config, live and in replay (a bad config keeps the old one); the run keeps
its record: counters, rejects, signal health, the sample index and, with the same model, the
learned estimate; the report lists each reload.
)";

using resolver::Calibration;
using resolver::CustomEffect;
using resolver::CustomEffectSpec;
using resolver::CustomEffects;
using resolver::DaemonConfig;
using resolver::Model;
using resolver::ModelSpec;
using resolver::ModelTerm;

/// The saved model, with the config's custom effects and the file's own.
Model model_from_calibration(const Calibration& cal, const DaemonConfig& config) {
  std::vector<CustomEffectSpec> specs = config.model.custom;
  for (const auto& c : cal.custom) {
    bool known = false;
    for (const auto& s : specs) known = known || s.name == c.name;
    if (!known) specs.push_back(CustomEffectSpec{c.name, c.signal, c.terms, "", "saved calibration"});
  }
  auto customs = std::make_shared<const CustomEffects>(specs);
  std::vector<std::string> names;
  for (const auto& p : cal.params) names.push_back(p.name);
  // A file without the model's references (an older method's, before they were
  // saved): the registry parameters it lists are the model.
  Model m(cal.model.empty() ? ModelSpec::for_parameters(names) : ModelSpec::parse(cal.model, customs.get()), cal.p_r,
          cal.p);
  m.keep(customs);
  for (const auto& p : cal.params) {
    try {
      m.set(p.name, p.value, p.std_error);
    } catch (const std::invalid_argument&) {
      // a parameter of another model (an older file): not part of this one
    }
  }
  return m;
}

/// The model's references and custom effects into the calibration (format 2).
void describe_model(const Model& model, Calibration& cal) {
  cal.model = model.spec().references();
  for (const ModelTerm& t : model.spec().terms) {
    if (const auto* c = dynamic_cast<const CustomEffect*>(t.effect)) {
      cal.custom.push_back({c->spec().name, c->spec().signal, c->spec().terms});
    }
  }
}

/// True when `url` (or LCM's default, "" = $LCM_DEFAULT_URL else udpm) is UDP multicast.
bool is_udpm(const std::string& url) {
  std::string_view u = url;
  if (u.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    u = env != nullptr ? std::string_view(env) : std::string_view("udpm://");
  }
  return u.empty() || u.substr(0, 7) == "udpm://";
}

}  // namespace

namespace {

/// resolverd's command line.
struct Options {
  std::string config_path, replay_path, can_iface, report_path, format_name, calibration_file, state_dir;
  std::optional<std::string> lcm_url;
  bool once = false, fast = false, quiet = false;
  double rate = 1.0;
  resolver::SampleSlice slice;
};

/// Parses the command line into `o`; an exit code when the program ends here (--help,
/// --version, CLI11's usage error). A --to before --from throws InputError (usage).
std::optional<int> parse_options(int argc, char** argv, Options& o) {
  using namespace resolver;
  CLI::App app{kDescription, "resolverd"};
  app.set_version_flag("--version", resolver::version_line("resolverd"));
  app.footer(exit_code::kHelpText);
  app.add_option("--config", o.config_path, "TOML config file (see README; every key optional)");
  auto* replay = app.add_option("--replay", o.replay_path,
                                "replay a log file instead of reading CAN: candump -l, Vector ASC or a CSV/scope export");
  auto* can = app.add_option("--can", o.can_iface, "read live frames from this SocketCAN interface (can0, vcan0)");
  replay->excludes(can);
  app.add_flag("--once", o.once, "with --replay: stop at the end of the log (default: loop it)")->needs(replay);
  auto* fast_opt =
      app.add_flag("--fast", o.fast, "with --replay: as fast as possible instead of the log's timing")->needs(replay);
  app.add_option("--rate", o.rate,
                 "with --replay: play at RATE times the log's own speed (default 1 = real time); "
                 "paces udpm for listeners that drop at --fast")
      ->needs(replay)
      ->excludes(fast_opt)
      ->check(CLI::PositiveNumber);
  app.add_option("--format", o.format_name,
                 "with --replay: candump, asc (Vector ASC) or csv (scope export, [input.csv] in --config); "
                 "default: [input] format, else the extension (.asc, .csv/.txt, else candump)")
      ->check(CLI::IsMember({"candump", "asc", "csv"}))
      ->needs(replay);
  app.add_option("--from", o.slice.from_s, "with --replay: process samples from this time on [s, 0 = the log's first sample]")
      ->check(CLI::NonNegativeNumber)
      ->needs(replay);
  app.add_option("--to", o.slice.to_s, "with --replay: stop after this time [s, from the log's first sample]")
      ->check(CLI::NonNegativeNumber)
      ->needs(replay);
  app.add_option("--lcm", o.lcm_url,
                 "LCM URL, overrides the config (default: LCM's udpm multicast; "
                 "'file:///path.lcmlog?mode=w' writes a log file, 'memq://' stays in-process)");
  app.add_option("--report", o.report_path, "also write the end-of-run report as JSON to this file");
  app.add_flag("--quiet", o.quiet, "no progress lines on stderr");
  app.add_option("--calibration", o.calibration_file,
                 "compensate with a table exported by 'resolver-model export LOG --table-format csv' instead of the live "
                 "estimate (the estimator still runs and publishes)")
      ->check(CLI::ExistingFile);
  app.add_option("--state-dir", o.state_dir,
                 "directory for the persisted calibration (systemd: $STATE_DIRECTORY); loaded at start unless it "
                 "was learned on another layout (then moved aside), saved at exit only from a healthy run (estimate "
                 "converged, model fit not unexplained, no lasting signal fault; else the reason is printed). "
                 "Locked while resolverd runs: a second resolverd on the same directory exits 3 naming the first's pid; "
                 "a save that fails exits 3");
  if (auto code = exit_code::parse_command_line(app, argc, argv)) return *code;
  exit_code::require_slice(o.slice);  // InputError: exit 2
  return std::nullopt;
}

/// --calibration TABLE.csv: compensate with an exported table.
void use_calibration_table(const std::string& calibration_file, resolver::Pipeline& pipeline) {
  using namespace resolver;
  try {
    CalibrationTable table = read_table_csv(calibration_file);
    std::cerr << "resolverd: compensating with the table " << calibration_file << " (" << table.correction.size()
              << " points, p_r " << table.p_r << ", interpolation error " << table.interpolation_error << " rad)\n";
    pipeline.use_table(std::move(table));
  } catch (const std::runtime_error& e) {  // not a table, a bad number, rows out of order
    throw InputError(Fault::kUsage, e.what(), Where::at_option("--calibration"));
  }
}

/// The state dir's calibration at start: refused and moved aside when learned on
/// another layout, else its Model compensates until this run has its own estimate.
void seed_from_state_dir(const std::string& state_dir, const resolver::DaemonConfig& config,
                         resolver::Pipeline& pipeline) {
  using namespace resolver;
  LoadResult loaded = load_calibration(state_dir);
  if (loaded.status == LoadResult::Status::kLoaded) {
    const Calibration::Provenance& saved = loaded.calibration->provenance;
    const LayoutIdentity here = layout_identity(config);  // ConfigError (the DBC): exit 2
    if (saved.layout_id.empty()) {
      std::cerr << "resolverd: " << calibration_path(state_dir)
                << " records no layout (written by an older resolverd); it is applied unchecked and the next save "
                   "records this run's layout\n";
    } else if (saved.layout_id != here.id) {
      std::string aside;
      try {
        aside = "kept aside as " + set_calibration_aside(state_dir, "refused-" + utc_now(true));
      } catch (const std::exception& e) {
        aside = std::string("and could not be kept aside (") + e.what() + ")";
      }
      std::cerr << "resolverd: the saved calibration " << calibration_path(state_dir) << " was learned on another layout ("
                << saved.layout << ", layout id " << saved.layout_id << ", from " << saved.source << " at "
                << saved.saved_at << ") than this run's (" << here.description << ", layout id " << here.id
                << "); it is NOT applied, "
                << aside
                << "; learning from scratch\n";
      loaded.status = LoadResult::Status::kMissing;
    }
  }
  if (loaded.status == LoadResult::Status::kLoaded) {
    const Calibration& cal = *loaded.calibration;
    // Every method compensates with the saved Model until this run has its own estimate.
    try {
      Model saved = model_from_calibration(cal, config);
      if (!saved.empty()) {
        std::cerr << "resolverd: compensating with the saved model ("
                  << fmt::format("{}", fmt::join(saved.spec().references(), ", ")) << ") from "
                  << calibration_path(state_dir) << " until this run's "
                  << (config.method == EstimatorMethod::kModel ? "first window is fitted" : "estimate converges")
                  << "\n";
        pipeline.seed_model(std::move(saved));
      }
    } catch (const std::exception& e) {
      std::cerr << "resolverd: the saved model in " << calibration_path(state_dir) << " is not used: " << e.what()
                << "\n";
    }
  } else if (loaded.status == LoadResult::Status::kRejected) {
    std::cerr << "resolverd: " << loaded.problem << "\n";
  }
}

/// Reads the input to its end (or a stop): the replayed log or the live interface.
/// Opening or reading it fails with std::system_error (exit 3), a CSV column map that
/// does not fit the export with ConfigError (exit 2): program_errors.h.
void read_input(const Options& o, const resolver::CanOptions& can, resolver::Pipeline& pipeline,
                const std::function<void()>& reload, resolver::StopFlags& flags, resolver::SdNotifier& notifier,
                resolver::RunInfo& info) {
  using namespace resolver;
  if (!o.replay_path.empty()) {
    ReplayOptions ro;
    ro.path = o.replay_path;
    ro.format = log_format_from_name(o.format_name);
    ro.fast = o.fast;
    ro.once = o.once;
    ro.rate = o.rate;
    ro.progress = !o.quiet;
    const ReplayResult rr = run_replay(ro, [&]() -> Pipeline& { return pipeline; }, reload, flags, std::cerr);
    info.source = o.replay_path;
    info.wall_seconds = rr.wall_seconds;
    return;
  }
  const auto live_start = std::chrono::steady_clock::now();
  run_live(LiveOptions{o.can_iface, notifier.enabled() ? &notifier : nullptr, can.receive_buffer_bytes, can.wake_auto,
                       can.wake_ids},
           [&]() -> Pipeline& { return pipeline; }, reload, flags, std::cerr);
  info.source = o.can_iface;
  info.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - live_start).count();
}

/// What the run's calibration needs beyond the pipeline: where it is saved and the provenance.
struct SaveContext {
  std::string state_dir, config_path, config_crc;
  const resolver::DaemonConfig* config = nullptr;
};

/// The calibration at exit: judged, saved or not, and why (into info); false when a
/// save failed (exit 3).
bool save_run_calibration(const SaveContext& ctx, const resolver::Pipeline& pipeline, resolver::RunInfo& info) {
  using namespace resolver;
  const std::string& state_dir = ctx.state_dir;
  if (state_dir.empty()) {
    info.calibration.reason = "no --state-dir given";
    return true;
  }
  info.calibration.path = calibration_path(state_dir);
  const CalibrationJudgement judged = judge_calibration(pipeline);
  if (!judged.trusted) {
    info.calibration.reason = judged.reason;
    std::cerr << "resolverd: calibration not saved to " << info.calibration.path << ": " << judged.reason
              << "; the file there, if any, is unchanged\n";
    return true;
  }
  const ModelEstimate model = pipeline.processor().estimate();
  Calibration cal;
  cal.p_r = pipeline.processor().config().p_r;
  cal.p = pipeline.processor().config().p;
  cal.method = model.method;
  cal.samples = model.samples;
  cal.params = model.params;
  describe_model(pipeline.processor().estimated_model(), cal);
  Calibration::Provenance& pv = cal.provenance;
  pv.config = ctx.config_path;
  pv.config_crc32 = ctx.config_crc;
  try {
    const LayoutIdentity layout = layout_identity(*ctx.config);
    pv.layout_id = layout.id;
    pv.layout = layout.description;
  } catch (const std::exception& e) {  // the DBC vanished since the start: save without it
    std::cerr << "resolverd: " << e.what() << "; the calibration is saved without its layout\n";
  }
  pv.source = info.source;
  pv.saved_at = utc_now();
  pv.program = version_line("resolverd");
  try {
    save_calibration(state_dir, cal);
    info.calibration.saved = true;
    std::cerr << "resolverd: calibration saved to " << info.calibration.path << "\n";
    return true;
  } catch (const std::exception& e) {  // InputError or IoError: either way nothing was saved
    info.calibration.reason = e.what();
    std::cerr << "resolverd: " << e.what() << " (exit code 3)\n";
    return false;
  }
}

/// The report (stdout and --report), the LCM output flushed, and the exit code.
int finish_outputs(const Options& o, resolver::LcmOutput& output, const resolver::Pipeline& pipeline,
                   const resolver::RunInfo& info, bool saved_or_not_asked) {
  using namespace resolver;
  print_run_report(std::cout, pipeline, info);
  int code = exit_code::kDone;
  (void)output.flush();
  if (output.publish_failures() > 0) {
    std::cerr << "resolverd: " << output.publish_failures() << " LCM publish calls failed";
    if (!output.write_error().empty()) std::cerr << " (" << output.write_error() << ")";
    std::cerr << "\n";
    if (!output.write_error().empty()) code = exit_code::kIo;  // the LCM log file is incomplete
  }
  if (!o.report_path.empty()) {
    std::ofstream out(o.report_path);
    out << run_report_json(pipeline, info);
    out.close();
    if (!out) {
      std::cerr << "resolverd: cannot write report " << o.report_path << ": " << std::strerror(errno) << "\n";
      return exit_code::kIo;
    }
  }
  if (!saved_or_not_asked) code = exit_code::kIo;
  if (code == exit_code::kDone && !o.replay_path.empty() && pipeline.samples() == 0) {
    std::cerr << "resolverd: " << o.replay_path << ": no sample decoded ("
              << pipeline.intake().stats().frames_seen << " frames seen); nothing was estimated or published "
                 "from it (exit code 1)\n";
    code = exit_code::kNoUsableData;
  }
  return code;
}

}  // namespace

static int run(int argc, char** argv) {
  using namespace resolver;
  Options o;
  if (auto code = parse_options(argc, argv, o)) return *code;
  const std::string& config_path = o.config_path;
  const std::optional<std::string>& lcm_url = o.lcm_url;
  // From here a SIGTERM is a request the run loop honours (it finds the flag set at
  // its first look), not the default death by signal, however early it comes.
  StopFlags flags;
  install_signal_handlers(flags);
  if (o.replay_path.empty() && o.can_iface.empty()) {
    throw InputError(Fault::kUsage, "nothing to read: give --replay LOG or --can IFACE (see --help)");
  }
  for (const auto& [option, path] : {std::pair{"--config", config_path}, std::pair{"--replay", o.replay_path}}) {
    if (!path.empty()) exit_code::require_readable(option, path);  // IoError: exit 3
  }

  DaemonConfig config;
  if (!config_path.empty()) config = load_daemon_config(config_path);  // ConfigError: exit 2
  if (lcm_url) config.lcm_url = *lcm_url;
  std::string config_crc = file_crc32(config_path);  // provenance of a saved calibration
  // Held for the whole run (see state_dir_lock.h); taken before anything is read from the directory.
  std::optional<StateDirLock> state_lock;
  if (!o.state_dir.empty()) state_lock = StateDirLock::acquire(o.state_dir);  // IoError: exit 3
  if (!config.dbc_path.empty()) {
    exit_code::require_readable("[layout] dbc", config.dbc_path, Where::at_file(config_path));  // IoError: exit 3
  }

  // LCM that cannot start throws std::system_error (exit 3); a DBC or signal map that
  // does not fit, ConfigError or std::invalid_argument (exit 2).
  const auto output = std::make_unique<LcmOutput>(config.lcm_url, config.channels);
  const auto pipeline = std::make_unique<Pipeline>(config, *output, std::cerr, !o.can_iface.empty(), o.slice);
  if (o.fast && is_udpm(config.lcm_url)) {
    std::cerr << "resolverd: --fast on udpm publishes as fast as the CPU allows (hundreds of thousands of messages/s); "
                 "listeners such as lcm-logger and lcm-spy drop what their socket buffers cannot hold. "
                 "To keep every message: pace it with --rate X (X times real time) instead of --fast, "
                 "or write a log with --lcm 'file:///PATH.lcmlog?mode=w' (stamped with bench time)\n";
  }

  if (!o.calibration_file.empty()) use_calibration_table(o.calibration_file, *pipeline);
  if (!o.state_dir.empty()) seed_from_state_dir(o.state_dir, config, *pipeline);
  SdNotifier notifier = SdNotifier::from_environment();
  if (!notifier.last_error().empty()) std::cerr << "resolverd: " << notifier.last_error() << "\n";

  RunInfo info;
  // SIGHUP: a valid new config is swapped into the running pipeline, which keeps the run's
  // record (counters, rejects, health, sample index, the learned estimate: Pipeline::reload).
  auto reload = [&]() {
    notifier.reloading();
    try {
      DaemonConfig fresh = config_path.empty() ? DaemonConfig{} : load_daemon_config(config_path);
      if (lcm_url) fresh.lcm_url = *lcm_url;
      const Pipeline::Reload& done = pipeline->reload(fresh);
      config = fresh;
      config_crc = file_crc32(config_path);
      std::cerr << "resolverd: config reloaded" << (config_path.empty() ? "" : " from " + config_path)
                << fmt::format(" at {:.3f} s into the input (sample {}): ", done.t_s, done.sample_index) << done.what
                << "\n";
    } catch (const std::exception& e) {
      std::cerr << "resolverd: reload failed, keeping the running config: " << e.what() << "\n";
    }
    notifier.ready();
  };
  read_input(o, config.can, *pipeline, reload, flags, notifier, info);
  const bool saved_or_not_asked = save_run_calibration({o.state_dir, config_path, config_crc, &config}, *pipeline, info);
  return finish_outputs(o, *output, *pipeline, info, saved_or_not_asked);
}

// Every failure that is an exception gets its exit code from the one rule
// (daemon/service/program_errors.h) and one line "resolverd: ...".
int main(int argc, char** argv) {
  return resolver::run_program("resolverd", [&] { return run(argc, argv); });
}
