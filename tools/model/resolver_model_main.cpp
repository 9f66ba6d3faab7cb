// resolver-model: offline model discovery on a candump log (issue 4, DESIGN 7).
//   resolver-model fit LOG [--effects a,b] [--json]
//   resolver-model explain LOG [--effects a,b] [--json]
//   resolver-model report LOG [--effects a,b] --html OUT.html [--max-steps N]
// All take --config FILE: a resolverd config whose [layout] (DBC, signal map),
// [input.csv] column map, [bench] pole pairs and [model] effects apply (logs of
// a user's own layout, scope exports), --format candump|asc|csv and --from/--to [s].
// Reads the log through resolverd's input path (tools/model/log_samples.h), fits the named catalog effects
// (default amplitude_imbalance), prints residuals against the noise floor and,
// for explain, the ranked missing effects and a verdict; report runs the
// discovery loop to its verdict and writes one self-contained HTML page of it.
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string_view>
#include <cstdio>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "tools/model/html_report.h"
#include "tools/model/log_samples.h"
#include "tools/model/model_report.h"
#include "daemon/service/program_version.h"

namespace {

/// A one-line progress bar on stderr, shown only once a run has taken longer
/// than 1.5 s (short logs stay quiet) and only when stderr is a terminal.
/// RESOLVER_PROGRESS=1 shows it on a pipe or file too, =0 never;
/// RESOLVER_PROGRESS_AFTER_MS changes the delay (tests use 0).
class ProgressBar {
 public:
  explicit ProgressBar(std::string label) : label_(std::move(label)), start_(Clock::now()) {
    const char* mode = std::getenv("RESOLVER_PROGRESS");
    enabled_ = mode != nullptr ? std::string_view(mode) != "0" : ::isatty(STDERR_FILENO) == 1;
    if (const char* ms = std::getenv("RESOLVER_PROGRESS_AFTER_MS")) {
      char* end = nullptr;
      const long v = std::strtol(ms, &end, 10);
      if (end != ms && *end == '\0' && v >= 0) show_after_ = std::chrono::milliseconds(v);  // else keep the default
    }
  }
  void operator()(double fraction) {
    if (!enabled_ || Clock::now() - start_ < show_after_) return;
    const int width = 30;
    const int filled = static_cast<int>(std::lround(std::clamp(fraction, 0.0, 1.0) * width));
    std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%%", label_.c_str(), filled, "##############################",
                 width - filled, "", fraction * 100.0);
    std::fflush(stderr);
    shown_ = true;
  }
  ~ProgressBar() {
    if (shown_) std::fprintf(stderr, "\n");
  }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

 private:
  using Clock = std::chrono::steady_clock;
  std::chrono::milliseconds show_after_{1500};
  bool enabled_ = false;
  std::string label_;
  Clock::time_point start_;
  bool shown_ = false;
};

std::vector<std::string> split_effects(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  for (const auto& a : args) {
    std::size_t b = 0;
    while (b <= a.size()) {
      const std::size_t e = a.find(',', b);
      const std::string name = a.substr(b, e == std::string::npos ? std::string::npos : e - b);
      if (!name.empty()) out.push_back(name);
      if (e == std::string::npos) break;
      b = e + 1;
    }
  }
  return out;
}

/// `report`: the discovery steps, the HTML page, one summary line and where it went.
int write_report(const resolver::LogSamples& samples, const std::string& log, const std::vector<std::string>& effects,
                 resolver::DiscoveryOptions options, int max_steps, const std::string& html_out) {
  options.series_points = 2000;  // per-sample plots: enough to show the ripple, ~100 kB per dotted plot
  resolver::DiscoveryRun run;
  {
    std::optional<ProgressBar> bar;  // one per step: the number of steps is not known ahead
    options.progress = [&](double f) { (*bar)(f); };
    run = resolver::run_discovery(samples.input, effects, options, max_steps, [&](int step) {
      bar.reset();
      bar.emplace("step " + std::to_string(step) + ": explaining");
    });
  }
  const std::string page = resolver::format_model_html(run, samples, log, options.explained_ratio);
  resolver::write_text_file(html_out, page);
  std::cout << resolver::summarize_discovery(run) << "\n"
            << "wrote " << html_out << " (" << (page.size() + 512) / 1024 << " KiB)\n";
  return 0;
}

int run(int argc, char** argv) {
  CLI::App app{"resolver-model: compare the effect model with a log, see where it fails, name the missing effect.\n"
               "Examples:\n"
               "  resolver-model fit build/demo/demo.log\n"
               "  resolver-model explain build/demo/demo.log\n"
               "  resolver-model explain demo.log --effects amplitude_imbalance,quadrature --json\n"
               "  resolver-model report build/demo/demo.log --html demo.html"};
  app.require_subcommand(1);
  app.set_version_flag("--version", resolver::version_line("resolver-model"));
  std::string log;
  std::vector<std::string> effects_args;
  std::string config_path;
  std::string format_name;
  resolver::SampleSlice slice;
  bool json = false;
  std::string fittable;
  for (auto e : resolver::fittable_effects()) fittable += (fittable.empty() ? "" : ", ") + std::string(e);
  auto add_common = [&](CLI::App* sub) {
    sub->add_option("LOG", log, "log: candump -l, Vector ASC or CSV (default bench layout unless --config)")->required();
    sub->add_option("--effects", effects_args,
                    "comma-separated catalog effects of the model (default amplitude_imbalance); fittable: " + fittable)
        ->delimiter(',');
    sub->add_flag("--json", json, "print one JSON object instead of the text report");
  };
  auto add_config = [&](CLI::App* sub) {
    sub->add_option("--config", config_path,
                    "resolverd config (TOML): its [layout] DBC and signals decode the log ([input.csv] a CSV), "
                    "[bench] p_r/p apply without BENCH_INFO, [model] effects is the model when --effects is not given")
        ->check(CLI::ExistingFile);
    sub->add_option("--format", format_name,
                    "log format: candump, asc (Vector ASC) or csv (scope export, needs [input.csv] in --config); "
                    "default: [input] format, else the extension (.asc, .csv/.txt, else candump)")
        ->check(CLI::IsMember({"candump", "asc", "csv"}));
    sub->add_option("--from", slice.from_s, "use samples from this time on [s, 0 = the log's first sample]")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--to", slice.to_s, "use samples up to this time [s, from the log's first sample]")
        ->check(CLI::NonNegativeNumber);
  };
  CLI::App* fit = app.add_subcommand("fit", "fit the model: parameters, residual vs noise floor, by harmonic and speed");
  CLI::App* explain = app.add_subcommand("explain", "fit, say where it fails and rank the missing catalog effects");
  add_common(fit);
  add_common(explain);
  CLI::App* report = app.add_subcommand(
      "report", "run the discovery loop (explain, add the best candidate, repeat) and write an HTML page with plots");
  std::string html_out;
  int max_steps = 6;
  report->add_option("LOG", log, "log: candump -l, Vector ASC or CSV (default bench layout unless --config)")->required();
  report->add_option("--effects", effects_args, "starting model, as for explain (default amplitude_imbalance)")->delimiter(',');
  report->add_option("--html", html_out, "HTML file to write (self-contained: inline CSS and SVG)")->required();
  report->add_option("--max-steps", max_steps, "at most this many explain passes (default 6)")->check(CLI::Range(1, 20));
  add_config(fit);
  add_config(explain);
  add_config(report);
  CLI11_PARSE(app, argc, argv);
  if (slice.to_s < slice.from_s) {
    std::cerr << "resolver-model: --to " << slice.to_s << " s is before --from " << slice.from_s << " s\n";
    return 2;
  }

  const bool do_explain = explain->parsed();
  try {
    resolver::DaemonConfig config;
    if (!config_path.empty()) config = resolver::load_daemon_config(config_path);  // throws naming file and key
    std::vector<std::string> effects = split_effects(effects_args);
    if (effects.empty()) effects = config.model.effects;  // default ["amplitude_imbalance"]
    resolver::LogSamples samples;
    {
      ProgressBar bar("reading " + log);
      resolver::LogReadOptions read_options;
      read_options.format = resolver::log_format_from_name(format_name);
      read_options.slice = slice;
      samples = resolver::read_log_samples(log, [&](double f) { bar(f); }, config, read_options);
    }
    resolver::DiscoveryOptions options;
    options.customs = config.model.customs.get();  // the config's [[model.custom]] effects
    if (report->parsed()) return write_report(samples, log, effects, options, max_steps, html_out);
    resolver::Explanation ex;
    {
      ProgressBar bar("fitting");
      options.progress = [&](double f) { bar(f); };
      if (do_explain) ex = resolver::explain_model(samples.input, effects, options);
      else ex.fit = resolver::fit_model(samples.input, effects, options);
    }
    std::vector<std::string> notes = samples.notes;
    if (samples.bad_lines > 0) notes.push_back(std::to_string(samples.bad_lines) + " malformed log lines skipped");
    if (samples.problems > 0) notes.push_back(std::to_string(samples.problems) + " decode problems (CRC, counters) skipped");
    std::cout << (json ? resolver::format_model_json(ex, do_explain, notes)
                       : resolver::format_model_text(ex, do_explain, notes));
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "resolver-model: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // e.g. out of memory while building the command line
    std::cerr << "resolver-model: " << e.what() << "\n";
    return 1;
  }
}
