// resolver-model: offline model discovery on a candump log (issue 4, DESIGN 7).
//   resolver-model fit LOG [--effects a,b] [--json]
//   resolver-model explain LOG [--effects a,b] [--json]
// Reads the log (default bench layout), fits the named catalog effects
// (default amplitude_imbalance), prints residuals against the noise floor and,
// for explain, the ranked missing effects and a verdict.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "tools/model/log_samples.h"
#include "tools/model/model_report.h"

namespace {

/// A one-line progress bar on stderr, shown only once a run has taken longer
/// than kShowAfter (short logs stay quiet) and only when stderr is a terminal
/// or RESOLVER_PROGRESS is set.
class ProgressBar {
 public:
  explicit ProgressBar(std::string label) : label_(std::move(label)), start_(Clock::now()) {}
  void operator()(double fraction) {
    if (Clock::now() - start_ < kShowAfter) return;
    const int width = 30;
    const int filled = static_cast<int>(fraction * width + 0.5);
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
  static constexpr std::chrono::milliseconds kShowAfter{1500};
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"resolver-model: compare the effect model with a log, see where it fails, name the missing effect.\n"
               "Examples:\n"
               "  resolver-model fit build/demo/demo.log\n"
               "  resolver-model explain build/demo/demo.log\n"
               "  resolver-model explain demo.log --effects amplitude_imbalance,quadrature --json"};
  app.require_subcommand(1);
  std::string log;
  std::vector<std::string> effects_args;
  bool json = false;
  std::string fittable;
  for (auto e : resolver::fittable_effects()) fittable += (fittable.empty() ? "" : ", ") + std::string(e);
  auto add_common = [&](CLI::App* sub) {
    sub->add_option("LOG", log, "candump -l log of the default bench layout")->required();
    sub->add_option("--effects", effects_args,
                    "comma-separated catalog effects of the model (default amplitude_imbalance); fittable: " + fittable)
        ->delimiter(',');
    sub->add_flag("--json", json, "print one JSON object instead of the text report");
  };
  CLI::App* fit = app.add_subcommand("fit", "fit the model: parameters, residual vs noise floor, by harmonic and speed");
  CLI::App* explain = app.add_subcommand("explain", "fit, say where it fails and rank the missing catalog effects");
  add_common(fit);
  add_common(explain);
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> effects = split_effects(effects_args);
  if (effects.empty()) effects.emplace_back("amplitude_imbalance");
  const bool do_explain = explain->parsed();
  try {
    resolver::LogSamples samples;
    {
      ProgressBar bar("reading " + log);
      samples = resolver::read_log_samples(log, [&](double f) { bar(f); });
    }
    resolver::DiscoveryOptions options;
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
