// resolver-sim: writes a candump -l log of the bench with chosen catalog effects.
// Wiring only: options -> SimConfig -> BenchSimulator -> CandumpWriter.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <toml++/toml.h>

#include "daemon/app/exit_codes.h"
#include "daemon/core/errors.h"
#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/quantization.h"
#include "drivers/candump/candump_writer.h"
#include "tools/sim/bench_simulator.h"
#include "tools/sim/sim_truth.h"
#include "daemon/service/program_version.h"

namespace {

using resolver::SimConfig;

constexpr double kBusFramesPerSecond = 8000.0;  // ~1 Mbit/s classic CAN, 8-byte standard frames

constexpr const char* kExamples = R"(
Examples:
  # Hwang's setup: 200 r/min, 0.3 % amplitude imbalance, 5 s
  resolver-sim --out imbalance.log --effect amplitude_imbalance:alpha=0.003
  # Constant 1000 r/min for 10 s, 12-bit converter, truth file for the report
  resolver-sim --out fast.log --rpm 1000 --duration 10 --rd-bits 12 --truth fast.json
  # Hold 200 r/min, ramp to 1000 r/min in 3 s, hold 2 s; several effects
  resolver-sim --out sweep.log --profile "200:5,200-1000:3,1000:2" \
      --effect quadrature:beta=0.004 --effect offsets:o_s=0.001,o_c=-0.002
  # Effects beyond the resolver windings: sampling skew (grows with speed),
  # eccentricity (1x mechanical), mounting offset (steady i_d against the reference),
  # current sensors (1x / 2x dq ripple) and dead time (6x dq ripple)
  resolver-sim --out bench.log --rpm 3000 --effect sampling_skew:tau=2e-6 \
      --effect eccentricity:e=5e-4,phase=1 --effect mounting_offset:theta_0=0.05 \
      --effect current_offsets:off_a=0.05,off_b=-0.03 --effect current_gain_mismatch:gain_a=0.01 \
      --effect dead_time:t_d=2e-6
  # An ideal chain: no noise, infinitely fast converter
  resolver-sim --out ideal.log --effect noise:sigma_sc=0,sigma_i=0 --effect tracking_loop:omega_n=0
  # Replay on a virtual bus:  canplayer -I imbalance.log vcan0=can0
Options can also come from --config FILE.toml (keys = long option names with '_'
for '-', effects = ["spec", ...]); options on the command line win.
)";

/// --rd-bits' range and default: the quantization effect's list, the one place they are written.
constexpr const resolver::ParamInfo& kRdBits = resolver::QuantizationParams::info("rd_bits");

struct Options {
  std::string out;
  std::string truth;
  std::string config_file;
  std::string profile_text;
  double rpm = 200.0;
  double duration = 5.0;
  int p_r = 3;
  int p = 3;
  int rd_bits = static_cast<int>(kRdBits.neutral);
  double sample_rate = 2000.0;
  double amplitude = 26000.0;
  double iq = 10.0;
  double alpha_drift = 0.0;
  double id = 0.0;
  std::vector<std::string> effects;
  bool no_reference = false;
  std::uint64_t seed = 1;
  std::string iface = "can0";
  bool list_effects = false;
  bool effects_markdown = false;
};

/// A refused option or config (exit 2), or a file that cannot be written (exit 3):
/// thrown, so run_program prints it and maps it by the one rule (no std::exit past
/// the destructors of a half-written log).
[[noreturn]] void fail(const std::string& message, int code = resolver::exit_code::kUsage) {
  if (code == resolver::exit_code::kIo) throw resolver::IoError(message);
  throw resolver::InputError(resolver::Fault::kUsage, message);
}

/// [rad per sample] the resolver electrical angle's travel per sample at which it
/// aliases: beyond pi a sampled angle cannot tell the speed from a slower (or
/// backwards) one, so the log would silently show another bench.
constexpr double kAliasingTravel = resolver::kPi;
/// [rad per sample] resolverd's overspeed line (daemon/core/health/signal_health.h:
/// the catalog's 4th harmonic of theta reaches Nyquist there).
constexpr double kOverspeedTravel = resolver::kPi / 4.0;

/// Refuses a speed the sample rate cannot represent (exit 2, naming the limit and the
/// options); warns above resolverd's overspeed line.
void check_speed(const SimConfig& c, bool profile) {
  double rpm = 0.0;
  for (const resolver::SpeedSegment& seg : c.profile) {
    rpm = std::max({rpm, std::abs(seg.rpm_start), std::abs(seg.rpm_end)});
  }
  const double per_rpm = static_cast<double>(c.p_r) * resolver::rpm_to_rad_s(1.0) / c.sample_rate_hz;  // rad/sample per r/min
  const double travel = rpm * per_rpm;
  const std::string option = profile ? "--profile" : "--rpm";
  if (travel >= kAliasingTravel) {
    fail(fmt::format("{} {:g} r/min is more than --sample-rate {:g} Hz can represent: the resolver electrical angle "
                     "(--p-r {}) would advance {:.2f} rad per sample, and from pi rad per sample on a sampled angle "
                     "aliases (the log would show a slower or backwards bench). The limit is {:.0f} r/min here; lower "
                     "{}, raise --sample-rate above {:.0f} Hz, or lower --p-r",
                     option, rpm, c.sample_rate_hz, c.p_r, travel, kAliasingTravel / per_rpm, option,
                     c.sample_rate_hz * travel / kAliasingTravel));
  }
  if (travel > kOverspeedTravel) {
    fmt::print(stderr,
               "resolver-sim: warning: {} {:g} r/min is {:.2f} rad of resolver electrical travel per sample, beyond "
               "pi/4 ({:.0f} r/min at --sample-rate {:g} Hz): resolverd will report overspeed and the estimators see "
               "fewer than 8 samples per electrical revolution\n",
               option, rpm, travel, kOverspeedTravel / per_rpm, c.sample_rate_hz);
  }
}

/// Fills options the command line did not set from a TOML file.
void apply_toml(const std::string& path, const CLI::App& app, Options& o, std::vector<std::string>& toml_effects) {
  toml::table table;
  try {
    table = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    fail(fmt::format("--config {}: {} (line {}); fix the TOML syntax", path, e.description(),
                     e.source().begin.line));
  }
  const auto unset = [&](const char* option) { return app.get_option(option)->count() == 0; };
  const auto number = [&](const std::string& key, const toml::node& node) {
    if (auto v = node.value<double>()) return *v;
    fail(fmt::format("--config {}: key '{}' must be a number", path, key));
  };
  const auto text = [&](const std::string& key, const toml::node& node) {
    if (auto v = node.value<std::string>()) return *v;
    fail(fmt::format("--config {}: key '{}' must be a string", path, key));
  };
  const auto integer = [&](const std::string& key, const toml::node& node) {
    if (node.is_integer()) return *node.value<std::int64_t>();  // value<int64_t>() of a float may overflow
    fail(fmt::format("--config {}: key '{}' must be an integer", path, key));
  };
  for (const auto& [key_node, node] : table) {
    const std::string key(key_node.str());
    if (key == "out") { if (unset("--out")) o.out = text(key, node); }
    else if (key == "truth") { if (unset("--truth")) o.truth = text(key, node); }
    else if (key == "profile") { if (unset("--profile") && unset("--rpm")) o.profile_text = text(key, node); }
    else if (key == "rpm") { if (unset("--rpm") && unset("--profile")) { o.rpm = number(key, node); o.profile_text.clear(); } }
    else if (key == "duration") { if (unset("--duration")) o.duration = number(key, node); }
    else if (key == "p_r") { if (unset("--p-r")) o.p_r = static_cast<int>(integer(key, node)); }
    else if (key == "p") { if (unset("--p")) o.p = static_cast<int>(integer(key, node)); }
    else if (key == "rd_bits") { if (unset("--rd-bits")) o.rd_bits = static_cast<int>(integer(key, node)); }
    else if (key == "sample_rate") { if (unset("--sample-rate")) o.sample_rate = number(key, node); }
    else if (key == "amplitude") { if (unset("--amplitude")) o.amplitude = number(key, node); }
    else if (key == "iq") { if (unset("--iq")) o.iq = number(key, node); }
    else if (key == "alpha_drift") { if (unset("--alpha-drift")) o.alpha_drift = number(key, node); }
    else if (key == "id") { if (unset("--id")) o.id = number(key, node); }
    else if (key == "seed") { if (unset("--seed")) o.seed = static_cast<std::uint64_t>(integer(key, node)); }
    else if (key == "iface") { if (unset("--iface")) o.iface = text(key, node); }
    else if (key == "reference") {
      const auto v = node.value<bool>();
      if (!v) fail(fmt::format("--config {}: key 'reference' must be true or false", path));
      if (unset("--no-reference")) o.no_reference = !*v;
    } else if (key == "effects") {
      const toml::array* arr = node.as_array();
      if (arr == nullptr) fail(fmt::format("--config {}: key 'effects' must be an array of spec strings", path));
      for (const toml::node& e : *arr) toml_effects.push_back(text("effects[]", e));
    } else {
      fail(fmt::format(
          "--config {}: unknown key '{}'; valid keys: out, truth, rpm, duration, profile, p_r, p, rd_bits, "
          "sample_rate, amplitude, iq, id, effects, reference, seed, iface",
          path, key));
    }
  }
}

SimConfig build_config(const CLI::App& app, const Options& o, const std::vector<std::string>& toml_effects) {
  SimConfig c;
  const bool rpm_given = app.get_option("--rpm")->count() > 0 || o.profile_text.empty();
  if (!o.profile_text.empty() && app.get_option("--duration")->count() > 0) {
    fail("--duration applies to --rpm; with --profile each segment carries its own seconds (rpm:seconds)");
  }
  if (!o.profile_text.empty()) {
    c.profile = resolver::parse_speed_profile(o.profile_text);  // InputError: exit 2
  } else if (rpm_given) {
    c.profile = {{o.duration, o.rpm, o.rpm}};
  }
  c.p_r = o.p_r;
  c.p = o.p;
  c.rd_bits = o.rd_bits;
  c.sample_rate_hz = o.sample_rate;
  c.amplitude_counts = o.amplitude;
  c.i_q_cmd = o.iq;
  c.alpha_drift_per_s = o.alpha_drift;
  c.i_d_cmd = o.id;
  c.reference = !o.no_reference;
  c.seed = o.seed;
  c.iface = o.iface;
  // TOML effects first, then the command line's: a later spec of the same parameter wins.
  for (const auto* list : {&toml_effects, &o.effects}) {
    for (const std::string& spec : *list) {
      try {
        c.chain.apply_spec(spec);
      } catch (const std::invalid_argument& e) {
        fail(fmt::format("--effect: {}", e.what()));
      }
    }
  }
  // --effect quantization:rd_bits=N and --rd-bits N are one setting.
  if (const int bits = static_cast<int>(c.chain.get("quantization", "rd_bits"));
      app.get_option("--rd-bits")->count() == 0 && bits != static_cast<int>(kRdBits.neutral)) {
    c.rd_bits = bits;
  }
  return c;
}

void add_options(CLI::App& app, Options& o) {
  app.add_option("--out,-o", o.out, "candump -l log file to write (required)");
  app.add_option("--rpm", o.rpm, "constant mechanical speed [r/min] (default 200)");
  app.add_option("--duration", o.duration, "run length with --rpm [s] (default 5)")->check(CLI::PositiveNumber);
  app.add_option("--profile", o.profile_text, "speed profile: rpm[-rpm_end]:seconds,... e.g. \"200:5,200-1000:3\"")
      ->excludes("--rpm");
  app.add_option("--p-r", o.p_r, "resolver pole pairs (default 3)")->check(CLI::Range(1, 255));
  app.add_option("--p", o.p, "motor pole pairs (default 3)")->check(CLI::Range(1, 255));
  app.add_option("--rd-bits", o.rd_bits, fmt::format("R/D converter resolution [bits] (default {})", kRdBits.neutral))
      ->check(CLI::Range(static_cast<int>(kRdBits.min), static_cast<int>(kRdBits.max)));
  app.add_option("--sample-rate", o.sample_rate, "control samples per second [Hz] (default 2000)")
      ->check(CLI::Range(1.0, 65535.0));
  app.add_option("--amplitude", o.amplitude, "sin/cos envelope amplitude [ADC counts] (default 26000)");
  app.add_option("--iq", o.iq, "commanded q current [A] (default 10)");
  app.add_option("--id", o.id, "commanded d current [A] (default 0)");
  app.add_option("--alpha-drift", o.alpha_drift,
                 "[1/s] let amplitude imbalance drift linearly in time (a winding warming up); NOT a catalog effect: "
                 "a test log for an error the model cannot name (default 0)");
  app.add_option("--effect,-e", o.effects, "effect spec effect:param=value,... (repeatable; see the catalog below)");
  app.add_flag("--no-reference", o.no_reference, "do not send REFERENCE_ANGLE frames");
  app.add_option("--seed", o.seed, "noise seed (default 1; same seed, same log)");
  app.add_option("--iface", o.iface, "interface name written into the log (default can0)");
  app.add_option("--truth", o.truth, "also write the true configuration and effect parameters as JSON");
  app.add_option("--config", o.config_file, "TOML file with the same options; the command line wins");
  app.add_flag("--list-effects", o.list_effects, "print the effect catalog and exit");
  app.add_flag("--effects-markdown", o.effects_markdown,
               "print the effect catalog as Markdown (docs/EFFECTS.md) and exit");
}

/// A warning when the log has more frames per second than a real bus carries.
void warn_if_over_bus_capacity(const SimConfig& config) {
  const double fps = resolver::frames_per_second(config);
  if (fps > kBusFramesPerSecond) {
    fmt::print(stderr,
               "resolver-sim: warning: {:.0f} frames/s exceed what a 1 Mbit/s classic CAN bus carries (~{:.0f}); "
               "the log is fine, but replaying it in real time will not fit a real bus (lower --sample-rate or use "
               "--no-reference)\n",
               fps, kBusFramesPerSecond);
  }
}

/// --truth FILE: the true configuration and effect parameters (exit 3 when it cannot be written).
void write_truth(const resolver::BenchSimulator& sim, std::uint64_t total, const Options& o) {
  std::ofstream truth(o.truth);
  truth << resolver::sim_truth_json(sim.config(), total, o.out);
  truth.close();
  if (!truth) {
    fail(fmt::format("--truth {}: cannot write the file; check the directory exists and is writable", o.truth),
         resolver::exit_code::kIo);
  }
}

/// Every sample's frames into the log (progress on stderr every 2 s), then the truth
/// file and one summary line. A log that cannot be created or written throws
/// std::system_error: exit 3.
void write_log(resolver::BenchSimulator& sim, const Options& o) {
  resolver::CandumpWriter writer(o.out);
  resolver::SimSample s{};
  std::vector<resolver::CanFrame> frames;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_report = t0;
  const std::uint64_t total = sim.total_samples();
  while (sim.next(s)) {
    frames.clear();
    sim.append_frames(s, frames);
    for (const resolver::CanFrame& f : frames) writer.write(f);
    const auto now = std::chrono::steady_clock::now();
    if (now - last_report > std::chrono::seconds(2)) {
      last_report = now;
      fmt::print(stderr, "resolver-sim: {:5.1f} % ({} of {} samples)\n", 100.0 * static_cast<double>(s.index + 1) /
                 static_cast<double>(total), s.index + 1, total);
    }
  }
  writer.close();
  if (!o.truth.empty()) write_truth(sim, total, o);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fmt::print(stderr, "resolver-sim: wrote {} frames ({} samples, {:.3g} s of bench time) to {} in {:.2f} s\n",
             writer.frames_written(), total, sim.profile().duration(), o.out, wall);
}

int run(int argc, char** argv) {
  CLI::App app{
      "resolver-sim: simulate the resolver bench (motor, resolver, R/D converter, inverter, reference encoder)\n"
      "and write its CAN traffic (the default layout, docs/ARCHITECTURE.md section 4) as a candump -l log, with chosen sensor-chain effects.",
      "resolver-sim"};  // the name in the usage line, not argv[0] (a build path)
  app.footer(std::string(kExamples) + "\n" + resolver::exit_code::kHelpText + "\n\n" +
             resolver::format_effect_catalog());
  app.set_version_flag("--version", resolver::version_line("resolver-sim"));
  Options o;
  add_options(app, o);
  if (auto code = resolver::exit_code::parse_command_line(app, argc, argv)) return *code;

  if (o.effects_markdown) {
    fmt::print("{}", resolver::effects_markdown());
    return 0;
  }
  if (o.list_effects) {
    fmt::print("{}", resolver::format_effect_catalog());
    return 0;
  }
  std::vector<std::string> toml_effects;
  if (!o.config_file.empty()) {
    resolver::exit_code::require_readable("--config", o.config_file);  // IoError: exit 3
    apply_toml(o.config_file, app, o, toml_effects);
  }
  if (o.out.empty()) fail("--out FILE is required (the candump log to write); see --help");

  const SimConfig config = build_config(app, o, toml_effects);
  check_speed(config, !o.profile_text.empty());
  std::optional<resolver::BenchSimulator> sim;
  try {
    sim.emplace(config);
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
  warn_if_over_bus_capacity(config);
  write_log(*sim, o);
  return 0;
}

}  // namespace

// What run() throws gets its exit code from the one rule (daemon/service/program_errors.h).
int main(int argc, char** argv) {
  return resolver::run_program("resolver-sim", [&] { return run(argc, argv); });
}
