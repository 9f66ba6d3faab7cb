// resolver-model: offline model discovery on a candump log (issue 4, docs/ARCHITECTURE.md §8).
//   resolver-model fit LOG [--effects a,b] [--json]
//   resolver-model explain LOG [--effects a,b] [--json]
//   resolver-model report LOG [--effects a,b] --html OUT.html [--max-steps N]
//   resolver-model export-data LOG [--effects a,b] --csv OUT.csv | --mat OUT.mat
//   resolver-model export LOG [--effects a,b] [--table-format csv|json|c-header] [--out FILE]
//   resolver-model fleet MANIFEST --out DIR [--effects a,b] | fleet --summarize DIR  (tools/model/fleet.h)
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
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "daemon/app/exit_codes.h"
#include "daemon/app/progress_meter.h"
#include "daemon/core/angles.h"
#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/model/calibration_table.h"
#include "daemon/core/model/model_spec.h"
#include "daemon/core/model/row_blocks.h"
#include "daemon/service/table_file.h"
#include "tools/model/export_data.h"
#include "tools/model/fleet.h"

#include <ctime>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include "tools/model/html_report.h"
#include "tools/model/log_samples.h"
#include "tools/model/model_report.h"
#include "tools/model/pooled_run.h"
#include "tools/model/stats_run.h"
#include "daemon/service/program_version.h"

namespace {

/// The effect references of every --effects argument, split at the commas outside
/// parentheses ("amplitude_imbalance,harmonics(k3,k5)" is two references).
std::vector<std::string> split_effects(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  for (const auto& a : args) {
    for (auto& one : resolver::split_effect_list(a)) out.push_back(std::move(one));
  }
  return out;
}

/// `report`: the discovery steps, the HTML page, one summary line and where it went.
int write_report(const resolver::LogSamples& samples, const std::string& log, const std::vector<std::string>& effects,
                 resolver::DiscoveryOptions options, int max_steps, const std::string& html_out,
                 const resolver::ProgressMeter::Options& progress) {
  options.series_points = 4000;  // the samples overlay: ~22 per 2 deg angle bin (report_data.h)
  resolver::DiscoveryRun run;
  {
    std::optional<resolver::ProgressMeter> bar;  // one per step: the number of steps is not known ahead
    options.progress = [&](double f) { bar->fraction(f); };
    run = resolver::run_discovery(samples.input, effects, options, max_steps, [&](int step) {
      bar.reset();
      bar.emplace(stderr, "step " + std::to_string(step) + ": explaining", progress);
    });
  }
  const std::string page = resolver::format_model_html(run, samples, log, options.explained_ratio);
  resolver::write_text_file(html_out, page);  // throws std::system_error: exit 3
  std::cout << resolver::summarize_discovery(run) << "\n"
            << "wrote " << html_out << " (" << (page.size() + 512) / 1024 << " KiB)\n";
  return 0;
}

/// `export`: fit, tabulate, write; one summary line on stderr.
/// A table whose interpolation error exceeds the model's noise floor corrects
/// the drive worse than the model does: says so on stderr, with the --points that
/// brings it under the floor (linear interpolation's error falls as 1/N^2).
void warn_if_coarse(const resolver::ModelFit& fit, const resolver::CalibrationTable& table, int points) {
  // Without a noise floor from the log: a 16-bit R/D converter's quantization floor.
  const bool have_floor = std::isfinite(fit.noise_floor_rad) && fit.noise_floor_rad > 0.0;
  const double floor = have_floor ? fit.noise_floor_rad : resolver::kTwoPi / 65536.0 / std::sqrt(12.0);
  if (!(table.interpolation_error > floor)) return;
  std::string better;
  constexpr int kMaxPoints = 1 << 20;  // --points' range
  int n = points;
  while (n < kMaxPoints && static_cast<double>(n) < points * std::sqrt(table.interpolation_error / floor)) n *= 2;
  for (; n <= kMaxPoints; n *= 2) {
    const double e = resolver::tabulate(fit.model, n).interpolation_error;
    if (e <= floor) {
      better = fmt::format("; --points {} gives {:.3g} rad", n, e);
      break;
    }
  }
  std::cerr << fmt::format(
      "resolver-model: warning: --points {}: the table's interpolation error {:.3g} rad is {:.3g}x {} ({:.3g} rad): "
      "the drive would correct worse than the model fits{}\n",
      points, table.interpolation_error, table.interpolation_error / floor,
      have_floor ? "the model's noise floor" : "a 16-bit R/D converter's quantization floor (the log gives no floor)",
      floor, better);
}

int write_export(const resolver::LogSamples& samples, const std::string& log, const std::vector<std::string>& effects,
                 const resolver::DiscoveryOptions& options, const std::string& format, int points,
                 const std::string& out) {
  const resolver::ModelFit fit = resolver::fit_model(samples.input, effects, options);
  const resolver::CalibrationTable table = resolver::tabulate(fit.model, points);
  const std::string text = resolver::calibration_text(table, log, format);
  if (out.empty()) std::cout << text;
  else resolver::write_text_file(out, text);
  std::cerr << "resolver-model: exported " << points << " points of " << fmt::format("{}", fmt::join(fit.effects, ", "))
            << " (position-error residual " << fit.residual_rms_rad << " rad, " << fit.residual_rms_rad / fit.noise_floor_rad
            << "x floor; interpolation error " << table.interpolation_error << " rad)" << (out.empty() ? "" : " to " + out)
            << "\n";
  warn_if_coarse(fit, table, points);
  return 0;
}

// --help examples, one block per subcommand ("Examples:" after the options: help2man
// makes it the man page's EXAMPLES section, cmake/MakeManPage.cmake sets it verbatim).
constexpr const char* kExamples = R"(Examples:
  # the demo log (tools/demo.sh): the seed model, then where it fails and what is missing
  resolver-model fit build/demo/demo.log
  resolver-model explain build/demo/demo.log
  # the discovery as one HTML page; the samples for MATLAB or pandas
  resolver-model report build/demo/demo.log --html demo.html
  resolver-model export-data build/demo/demo.log --csv demo.csv --mat demo.mat
  # a correction table for the drive firmware
  resolver-model export build/demo/demo.log --effects amplitude_imbalance --table-format c-header --out table.h
  # a production line: every unit of a manifest (CSV unit,log), one folder each, and fleet.json
  resolver-model fleet units.csv --out fleet/
Each subcommand's --help has its options and examples: resolver-model fit --help)";

constexpr const char* kFitExamples = R"(Examples:
  # the default model (amplitude_imbalance, or the config's [model] effects)
  resolver-model fit build/demo/demo.log
  # two effects, as JSON; only seconds 1..4 of a Vector ASC log
  resolver-model fit demo.log --effects amplitude_imbalance,dead_time --json
  resolver-model fit bench.asc --from 1 --to 4
  # a scope export mapped by [input.csv] in a resolverd config; forward motion only
  resolver-model fit scope.csv --config scope.toml --direction forward
  # one motor's runs of a week fitted together; each run's own fit against the pool
  resolver-model fit mon.log tue.log wed.log --effects amplitude_imbalance,quadrature --jobs 2)";

constexpr const char* kExplainExamples = R"(Examples:
  # where the seed model fails and the ranked missing effects
  resolver-model explain build/demo/demo.log
  # the same from a richer model, as JSON (suggested_custom: a [[model.custom]] block)
  resolver-model explain demo.log --effects amplitude_imbalance,quadrature --json
  # with the effects of a resolverd config (its [model] effects and [[model.custom]] blocks)
  resolver-model explain demo.log --config tools/demo/model_with_dead_time.toml
  # several runs of one bench together: what they share is fitted once, and they are
  # told apart only by their reference zero, amplitude and operating point
  resolver-model explain run1.log run2.log --json)";

constexpr const char* kReportExamples = R"(Examples:
  # the discovery loop to its verdict, as one self-contained page
  resolver-model report build/demo/demo.log --html demo.html
  # start from two effects, at most 3 steps
  resolver-model report demo.log --effects amplitude_imbalance,dead_time --max-steps 3 --html demo.html)";

constexpr const char* kExportDataExamples = R"(Examples:
  # samples, prediction and residual per sample: CSV (+ demo.params.csv) and .mat
  resolver-model export-data build/demo/demo.log --csv demo.csv --mat demo.mat
  # the model with dead time, the first 2 s only, .mat alone
  resolver-model export-data demo.log --effects amplitude_imbalance,dead_time --to 2 --mat demo.mat
  # read back:  MATLAB  s = load('demo.mat'); T = readtable('demo.csv');
  #             Python  scipy.io.loadmat('demo.mat', squeeze_me=True); pandas.read_csv('demo.csv'))";

constexpr const char* kExportExamples = R"(Examples:
  # a CSV table that resolverd --calibration compensates with
  resolver-model export build/demo/demo.log --effects amplitude_imbalance,dead_time --out table.csv
  resolverd --replay build/demo/demo.log --once --fast --calibration table.csv
  # a C header for the drive firmware, 256 points per mechanical turn
  resolver-model export demo.log --table-format c-header --points 256 --out resolver_table.h)";

constexpr const char* kFleetExamples = R"(Examples:
  # units.csv: a header "unit,log", then one row per log (a unit may have several;
  # relative paths are relative to the manifest's folder)
  resolver-model fleet units.csv --out fleet/
  # a richer model for every unit; only recompute fleet/fleet.json from fleet/*/unit.json
  resolver-model fleet units.csv --out fleet/ --effects amplitude_imbalance,quadrature
  resolver-model fleet --summarize fleet/
  # the statistics made elsewhere (one `resolver-model stats LOG --out fleet/UNIT/stats/LINE.stats`
  # per manifest row, LINE its line in units.csv): merge each unit and summarize
  resolver-model fleet units.csv --out fleet/ --merge-only
  # the same on a Dask cluster (one task per log, the merge here): python3 -m resolver_bench.fleet
Writes OUT/UNIT/stats/LINE.stats per manifest row (stats's file; LINE.error with the reason
when the log fails), OUT/UNIT/unit.json (the merge of the unit's statistics: verdict, residual
vs floor, parameters with standard errors, each log's own fit, parameters the unit's logs
disagree on), OUT/UNIT/calibration.{csv,json,h} (export's formats, of the merged parameters)
and OUT/fleet.json (per parameter
median, robust spread = 1.4826 MAD and quantiles; proposed effects; outlier units, robust z > 4;
failed units with the reason) with OUT/fleet.html, the same on one self-contained page (every
parameter's strip plot with the outliers named, the effects the units need, every unit's row).
A unit fails, and the others go on, when a log is missing, unreadable or has no usable
data (or has no statistics file with --merge-only), is listed twice, or has another p_r
than the fleet; unit.json names each such log with its manifest line and reason.
Exit 0 when every unit is done, 1 when some unit failed (fleet.json says which and why).)";

constexpr const char* kStatsExamples = R"(Examples:
  # one run's statistics (the model fitted to it, then one pass with every candidate's columns)
  resolver-model stats mon.log --effects amplitude_imbalance,quadrature,tracking_loop --out mon.stats
  # the second half of a long log only
  resolver-model stats endurance.log --from 1800 --out endurance_2.stats
Writes self-describing JSON (format, version, tool, layout, bench, model, columns, each
signal group's normal equations per validation fold, noise floors, counts) that merge reads.)";

constexpr const char* kMergeExamples = R"(Examples:
  # a week of runs of one motor fitted together from their statistics (no logs needed)
  resolver-model merge mon.stats tue.stats wed.stats
  # another model from the same statistics (its effects must be each file's model or candidates)
  resolver-model merge mon.stats tue.stats --effects amplitude_imbalance,quadrature --json
Each run keeps its own reference zero, amplitude and operating point, as in fit A.log B.log
(the chunks of one log, stats --chunk, share its reference zero);
linear parameters merge exactly, nonlinear ones to second order in how far the runs' own
fits lie apart (a note says how far). Files of another version or layout are refused (exit 2).)";

/// A subcommand's footer: its examples, then the exit codes every --help ends with.
std::string sub_footer(const char* examples) {
  return std::string(examples) + "\n\n" + resolver::exit_code::kHelpText;
}

/// `fleet`: every unit of MANIFEST into OUT, then OUT/fleet.json; or --summarize DIR alone.
int run_fleet(const std::string& manifest, const std::string& out, const std::string& summarize_dir,
              std::vector<std::string> effects, const std::string& config_path, int points, bool merge_only) {
  using resolver::Fault, resolver::InputError, resolver::Where;
  if (!summarize_dir.empty() && (!manifest.empty() || !out.empty())) {
    throw InputError(Fault::kUsage, "--summarize DIR takes no MANIFEST or --out", Where::at_option("fleet"));
  }
  if (!summarize_dir.empty() && merge_only) {
    throw InputError(Fault::kUsage, "--merge-only needs MANIFEST --out DIR, not --summarize", Where::at_option("fleet"));
  }
  int failed = 0;
  if (!summarize_dir.empty()) {
    if (!std::filesystem::is_directory(summarize_dir)) {
      throw resolver::IoError("--summarize " + summarize_dir + ": not a folder", Where::at_option("fleet"));
    }
    std::cout << resolver::summarize_fleet(summarize_dir, failed);
    return failed > 0 ? resolver::exit_code::kNoUsableData : resolver::exit_code::kDone;
  }
  if (manifest.empty() || out.empty()) {
    throw InputError(Fault::kUsage, "give MANIFEST --out DIR, or --summarize DIR", Where::at_option("fleet"));
  }
  resolver::exit_code::require_readable("MANIFEST", manifest);  // IoError: exit 3
  resolver::FleetOptions options;
  if (!config_path.empty()) options.config = resolver::load_daemon_config(config_path);
  if (!effects.empty()) {
    try {
      (void)resolver::ModelSpec::parse(effects, options.config.model.customs.get());
    } catch (const std::invalid_argument& e) {
      throw resolver::InputError(resolver::Fault::kUsage, e.what(), resolver::Where::at_option("--effects"));
    }
  } else {
    effects = options.config.model.effects;
  }
  options.effects = effects;
  options.points = points;
  options.merge_only = merge_only;
  options.discovery = resolver::offline_discovery_options();
  options.discovery.customs = options.config.model.customs.get();
  options.discovery.prepare.reference_aligned = options.config.bench.reference_aligned;
  const std::vector<resolver::ManifestRow> rows = resolver::read_manifest(manifest);
  std::filesystem::create_directories(out);
  (void)resolver::run_fleet_units(rows, manifest, out, options);
  std::cout << resolver::summarize_fleet(out, failed);
  return failed > 0 ? resolver::exit_code::kNoUsableData : resolver::exit_code::kDone;
}

/// The subcommands; several share an argument (LOG, --effects, --config, ...).
enum class Command { kFit, kExplain, kReport, kExportData, kExport, kFleet, kStats, kMerge };

/// Every value the command line sets, one field per option whatever subcommand gives it.
struct Arguments {
  Command command = Command::kFit;
  std::string log;                // the first of `logs` for fit and explain
  std::vector<std::string> logs;  // fit, explain: two or more make a pooled fit
  int jobs = 1;                   // pooled: logs read at once
  std::vector<std::string> effects_args;
  std::string config_path;
  std::string format_name;
  resolver::SampleSlice slice;
  bool json = false;
  bool progress = false;
  std::string direction = "both";
  bool moving_only = false;
  bool reference_aligned = false;
  std::string html_out;  // report
  int max_steps = 6;
  std::string csv_out, mat_out;  // export-data
  std::string export_format = "csv", export_out;  // export
  int export_points = 1024;  // export and fleet
  std::string manifest, fleet_out, summarize_dir;  // fleet
  bool merge_only = false;                         // fleet
  std::string stats_out;                // stats
  double chunk_s = 0.0;                 // stats: one run per chunk of this many seconds
  std::vector<std::string> stats_files;  // merge
  int threads = 0;                       // passes over a log's rows (0: every core)
};

/// Threads for the passes over a log's rows (row_blocks.h: the answer does not depend on it).
void add_threads_option(CLI::App* sub, Arguments& a) {
  sub->add_option("--threads", a.threads,
                  "threads each pass over the log's rows uses (default: every core; the result is the same to the "
                  "last bit with any number)")
      ->check(CLI::Range(1, 1024));
}

/// fit and explain: the log, the model (with the fittable effects listed) and --json.
void add_model_options(CLI::App* sub, Arguments& a, const std::string& fittable) {
  sub->add_option("LOG", a.logs,
                  "log: candump -l, Vector ASC or CSV (default bench layout unless --config); two or more logs of one "
                  "bench are fitted together (shared sensor parameters, each log its own reference zero, amplitude "
                  "and operating point), and each log's own fit is compared with the pool")
      ->required();
  sub->add_option("--jobs", a.jobs, "pooled fit: read this many logs at once (default 1)")->check(CLI::Range(1, 256));
  sub->add_option("--effects", a.effects_args,
                  "the model: comma-separated effect references, an effect by name (its default parameters) or "
                  "with a parameter list, e.g. amplitude_imbalance,harmonics(k5,k3_opp),delay; catalog effects or "
                  "the config's [[model.custom]] names (default amplitude_imbalance); fittable: " + fittable);
  sub->add_flag("--json", a.json, "print one JSON object instead of the text report");
}

/// Which of the log's samples a fit uses.
void add_slicing_options(CLI::App* sub, Arguments& a) {
  sub->add_option("--direction", a.direction,
                  "fit only the samples moving this way: forward, backward or both (default both); the others are "
                  "counted as excluded")
      ->check(CLI::IsMember({"forward", "backward", "both"}));
  sub->add_flag("--reference-aligned", a.reference_aligned,
                "the reference encoder's zero is on the rotor d axis (as resolver-sim's is; [bench] "
                "reference_aligned): a constant position error is then the mounting offset, not a free constant");
  sub->add_flag("--moving-only", a.moving_only,
                "leave standstill samples out of everything, the noise floor too (default: they give the floor "
                "and never enter a fit)");
  add_threads_option(sub, a);
}

/// How the log is read: config, format, time range and progress.
void add_config_options(CLI::App* sub, Arguments& a) {
  sub->add_option("--config", a.config_path,
                  "resolverd config (TOML): its [layout] DBC and signals decode the log ([input.csv] a CSV), "
                  "[bench] p_r/p apply without BENCH_INFO, [model] effects is the model when --effects is not given");
  sub->add_option("--format", a.format_name,
                  "log format: candump, asc (Vector ASC) or csv (scope export, needs [input.csv] in --config); "
                  "default: [input] format, else the extension (.asc, .csv/.txt, else candump)")
      ->check(CLI::IsMember({"candump", "asc", "csv"}));
  sub->add_option("--from", a.slice.from_s, "use samples from this time on [s, 0 = the log's first sample]")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--to", a.slice.to_s, "use samples up to this time [s, from the log's first sample]")
      ->check(CLI::NonNegativeNumber);
  sub->add_flag("--progress", a.progress,
                "show progress on stderr (bytes read of the total, samples, rate, ETA; then the fit) even when it "
                "is not a terminal, one line per update; on a terminal it is shown anyway once a run takes 1.5 s");
}

/// The subcommands as added to the app, to tell after parsing which one was given.
struct Subcommands {
  CLI::App* fit = nullptr;
  CLI::App* explain = nullptr;
  CLI::App* report = nullptr;
  CLI::App* export_data = nullptr;
  CLI::App* exporter = nullptr;
  CLI::App* fleet = nullptr;
  CLI::App* stats = nullptr;
  CLI::App* merge = nullptr;

  [[nodiscard]] Command parsed() const {
    if (stats->parsed()) return Command::kStats;
    if (merge->parsed()) return Command::kMerge;
    if (explain->parsed()) return Command::kExplain;
    if (report->parsed()) return Command::kReport;
    if (export_data->parsed()) return Command::kExportData;
    if (exporter->parsed()) return Command::kExport;
    if (fleet->parsed()) return Command::kFleet;
    return Command::kFit;
  }
};

/// fit, explain, report and export-data, in this order (--help lists them so).
void add_discovery_subcommands(CLI::App& app, Arguments& a, Subcommands& subs) {
  std::string fittable;
  for (auto e : resolver::fittable_effects()) fittable += (fittable.empty() ? "" : ", ") + std::string(e);
  subs.fit = app.add_subcommand("fit", "fit the model: parameters, residual vs noise floor, by harmonic and speed");
  subs.explain = app.add_subcommand("explain", "fit, say where it fails and rank the missing catalog effects");
  add_model_options(subs.fit, a, fittable);
  add_model_options(subs.explain, a, fittable);
  for (CLI::App* sub : {subs.fit, subs.explain}) {
    sub->add_option("--chunk", a.chunk_s,
                    "one log of any length in the memory of two chunks: each chunk of this many seconds is fitted "
                    "as a run and the runs merged (as stats --chunk then merge; the report is merge's: no "
                    "breakdowns by harmonic or speed)")
        ->check(CLI::PositiveNumber);
  }
  subs.fit->footer(sub_footer(kFitExamples));
  subs.explain->footer(sub_footer(kExplainExamples));
  CLI::App* report = subs.report = app.add_subcommand(
      "report", "run the discovery loop (explain, add the best candidate, repeat) and write an HTML page with plots");
  report->footer(sub_footer(kReportExamples));
  report->add_option("LOG", a.logs,
                     "log: candump -l, Vector ASC or CSV (default bench layout unless --config); two or more logs "
                     "of one bench: the loop runs on them pooled (as fit A.log B.log)")
      ->required();
  report->add_option("--jobs", a.jobs, "pooled: read this many logs at once (default 1)")->check(CLI::Range(1, 256));
  report->add_option("--effects", a.effects_args, "starting model, as for explain (default amplitude_imbalance)");
  report->add_option("--html", a.html_out, "HTML file to write (self-contained: inline CSS and SVG)")->required();
  report->add_option("--max-steps", a.max_steps, "at most this many explain passes (default 6)")->check(CLI::Range(1, 20));
  CLI::App* export_data = subs.export_data = app.add_subcommand(
      "export-data", "write the log's samples, the fitted model's prediction and residual per sample, and the "
                     "parameters with units: CSV (MATLAB readtable, pandas) and/or MATLAB .mat");
  export_data->footer(sub_footer(kExportDataExamples));
  export_data->add_option("LOG", a.log, "log: candump -l, Vector ASC or CSV (default bench layout unless --config)")->required();
  export_data->add_option("--effects", a.effects_args, "the model, as for fit (default amplitude_imbalance)");
  export_data->add_option("--csv", a.csv_out, "CSV of the samples [one header line, units in the column names]; the "
                                              "parameters go to OUT's stem + .params.csv");
  export_data->add_option("--mat", a.mat_out, "MATLAB MAT-5 file: structs samples, units, descriptions, params, info");
  for (CLI::App* sub : {subs.fit, subs.explain, report, export_data}) {
    add_config_options(sub, a);
    add_slicing_options(sub, a);
  }
}

/// stats and merge: statistics that merge (issue 24).
void add_statistics_subcommands(CLI::App& app, Arguments& a, Subcommands& subs) {
  CLI::App* stats = subs.stats = app.add_subcommand(
      "stats", "fit the model to one log and write its statistics (normal equations of the model and every "
               "candidate, floors, counts) for merge");
  stats->footer(sub_footer(kStatsExamples));
  stats->add_option("LOG", a.log, "log: candump -l, Vector ASC or CSV (default bench layout unless --config)")->required();
  stats->add_option("--effects", a.effects_args, "the model, as for fit (default amplitude_imbalance)");
  stats->add_option("--out", a.stats_out, "statistics file to write (JSON)")->required();
  stats->add_option("--chunk", a.chunk_s,
                    "read the log in chunks of this many seconds, each a run of its own (its own amplitude and "
                    "operating point; the log's reference zero shared when merged): a log of any length in the "
                    "memory of two chunks; a last piece shorter than half a chunk joins the one before")
      ->check(CLI::PositiveNumber);
  add_config_options(stats, a);
  add_slicing_options(stats, a);
  CLI::App* merge = subs.merge = app.add_subcommand(
      "merge", "fit several runs of one bench from their statistics files (resolver-model stats), without the logs");
  merge->footer(sub_footer(kMergeExamples));
  merge->add_option("STATS", a.stats_files, "statistics files written by resolver-model stats")->required();
  merge->add_option("--effects", a.effects_args,
                    "the model (default: the first file's); each parameter must be a column of every file");
  merge->add_flag("--json", a.json, "print one JSON object instead of the text report");
  merge->add_option("--config", a.config_path, "resolverd config (TOML): its [[model.custom]] effects");
}

/// export and fleet, after the others.
void add_calibration_subcommands(CLI::App& app, Arguments& a, Subcommands& subs) {
  CLI::App* exporter = subs.exporter = app.add_subcommand(
      "export", "fit the model and write what a drive firmware loads: a correction table over one mechanical "
                "revolution with its harmonic coefficients (resolverd --calibration reads the CSV)");
  exporter->footer(sub_footer(kExportExamples));
  exporter->add_option("LOG", a.log, "the log to fit (as for fit)")->required();
  exporter->add_option("--effects", a.effects_args, "the model, as for fit (default amplitude_imbalance)");
  exporter->add_option("--table-format", a.export_format, "the table's format: csv (default), json or c-header")
      ->check(CLI::IsMember({"csv", "json", "c-header"}));
  exporter->add_option("--points", a.export_points, "table points over one mechanical revolution (default 1024)")
      ->check(CLI::Range(8, 1 << 20));
  exporter->add_option("--out", a.export_out, "file to write (default: standard output)");
  add_config_options(exporter, a);
  add_slicing_options(exporter, a);
  CLI::App* fleet = subs.fleet = app.add_subcommand(
      "fleet", "a production line: explain and calibrate every unit of a manifest (CSV unit,log), one folder per "
               "unit, and summarize the fleet (spread, outliers, failed units) in OUT/fleet.json");
  fleet->footer(sub_footer(kFleetExamples));
  fleet->add_option("MANIFEST", a.manifest, "CSV with the header unit,log; one row per log");
  fleet->add_option("--out", a.fleet_out, "folder for OUT/UNIT/ and OUT/fleet.json (created)");
  fleet->add_option("--summarize", a.summarize_dir,
                    "only recompute DIR/fleet.json from DIR/*/unit.json (units run elsewhere, e.g. on Dask)");
  fleet->add_flag("--merge-only", a.merge_only,
                  "only merge the statistics already in OUT/UNIT/stats/LINE.stats (written by resolver-model stats "
                  "elsewhere) and summarize");
  fleet->add_option("--effects", a.effects_args, "the model every log is fitted with, as for stats");
  fleet->add_option("--points", a.export_points, "calibration table points per mechanical revolution (default 1024)")
      ->check(CLI::Range(8, 1 << 20));
  fleet->add_option("--config", a.config_path, "resolverd config (TOML), as for explain");
  add_threads_option(fleet, a);
  add_statistics_subcommands(app, a, subs);
}

/// A usage error (InputError: exit 2) or an unreadable input (IoError: exit 3), thrown
/// before anything is read.
void check_arguments(const Arguments& a) {
  resolver::exit_code::require_slice(a.slice);
  for (const auto& [option, path] : {std::pair{"LOG", a.log}, std::pair{"--config", a.config_path}}) {
    if (!path.empty()) resolver::exit_code::require_readable(option, path);
  }
  if (a.command == Command::kExportData && a.csv_out.empty() && a.mat_out.empty()) {
    throw resolver::InputError(resolver::Fault::kUsage, "give --csv OUT, --mat OUT or both",
                               resolver::Where::at_option("export-data"));
  }
}

/// The config (its defaults without --config) and the model's effects.
struct Model {
  resolver::DaemonConfig config;
  std::vector<std::string> effects;
};

/// --effects, checked before the log is read, else the config's [model] effects.
Model load_model(const Arguments& a) {
  Model m;
  if (!a.config_path.empty()) m.config = resolver::load_daemon_config(a.config_path);  // throws naming file and key
  m.effects = split_effects(a.effects_args);
  if (!m.effects.empty()) {
    // A misspelt effect is a usage error, found before the log is read (the
    // config's [model] effects were checked when it was loaded).
    try {
      (void)resolver::ModelSpec::parse(m.effects, m.config.model.customs.get());
    } catch (const std::invalid_argument& e) {
      throw resolver::InputError(resolver::Fault::kUsage, e.what(), resolver::Where::at_option("--effects"));
    }
  }
  if (m.effects.empty()) m.effects = m.config.model.effects;  // default ["amplitude_imbalance"]
  return m;
}

/// The log's samples, with a progress bar while it is read.
/// `on_chunk` (stats --chunk): the samples go there chunk by chunk instead of into the result.
resolver::LogSamples read_samples(const Arguments& a, const resolver::DaemonConfig& config,
                                  const resolver::ProgressMeter::Options& shown,
                                  const std::function<void(resolver::DiscoveryInput&&)>& on_chunk = {}) {
  resolver::LogSamples samples;
  {
    resolver::ProgressMeter bar(stderr, "reading " + a.log, shown);
    resolver::LogReadOptions read_options;
    read_options.format = resolver::log_format_from_name(a.format_name);
    read_options.slice = a.slice;
    if (on_chunk) {
      read_options.chunk_s = a.chunk_s;
      read_options.on_chunk = on_chunk;
    }
    samples = resolver::read_log_samples(
        a.log, [&](const resolver::LogReadProgress& p) { bar.bytes(p.bytes_read, p.total_bytes, p.samples, p.done); },
        config, read_options);
  }
  if (!samples.grew_while_read.empty()) std::cerr << "resolver-model: warning: " << samples.grew_while_read << "\n";
  return samples;
}

/// The offline discovery settings with the command line's slicing and the config's custom effects.
resolver::DiscoveryOptions discovery_options(const Arguments& a, const resolver::DaemonConfig& config) {
  resolver::DiscoveryOptions options = resolver::offline_discovery_options();
  options.customs = config.model.customs.get();  // the config's [[model.custom]] effects
  options.prepare.direction = a.direction == "forward"    ? resolver::DirectionFilter::kForward
                              : a.direction == "backward" ? resolver::DirectionFilter::kBackward
                                                          : resolver::DirectionFilter::kBoth;
  options.prepare.moving_only = a.moving_only;
  options.prepare.reference_aligned = a.reference_aligned || config.bench.reference_aligned;
  return options;
}

/// Faults over a tenth of the log forbid "explained"; shorter ones are notes.
void weigh_signal_faults(resolver::LogSamples& samples, resolver::DiscoveryOptions& options) {
  const resolver::FaultCounts faults = resolver::fault_counts(samples);
  options.untrusted_input = resolver::lasting_faults(faults, samples.health_samples, resolver::kUntrustedFaultShare);
  for (const std::string& f : resolver::lasting_faults(faults, samples.health_samples, 0.0)) {
    samples.notes.push_back("signal health: " + f);
  }
}

/// report, export or export-data: the files they write.
int write_outputs(const Arguments& a, const resolver::LogSamples& samples, const std::vector<std::string>& effects,
                  const resolver::DiscoveryOptions& options, const resolver::ProgressMeter::Options& shown) {
  // The effects were checked before the log was read: what the fit refuses now
  // (too few samples, the rotor hardly moves, no angle signal) is the data's fault.
  try {
    if (a.command == Command::kReport) {
      return write_report(samples, a.log, effects, options, a.max_steps, a.html_out, shown);
    }
    if (a.command == Command::kExport) {
      return write_export(samples, a.log, effects, options, a.export_format, a.export_points, a.export_out);
    }
    std::cout << resolver::export_data(samples.input, effects, options, a.log, a.csv_out, a.mat_out);
    return 0;
  } catch (const std::invalid_argument& e) {
    throw resolver::InputError(resolver::Fault::kData, e.what(), resolver::Where::at_file(a.log));
  }
}

/// fit or explain, with a progress bar; a fit the data refuses is the data's fault.
resolver::Explanation fit_or_explain(const resolver::LogSamples& samples, const std::string& log,
                                     const std::vector<std::string>& effects, resolver::DiscoveryOptions options,
                                     bool explain, const resolver::ProgressMeter::Options& shown) {
  resolver::Explanation ex;
  try {
    resolver::ProgressMeter bar(stderr, "fitting", shown);
    options.progress = [&](double f) { bar.fraction(f); };
    if (explain) ex = resolver::explain_model(samples.input, effects, options);
    else ex.fit = resolver::fit_model(samples.input, effects, options);
    bar.fraction(1.0);  // fit_model reports only its first steps
  } catch (const std::invalid_argument& e) {
    throw resolver::InputError(resolver::Fault::kData, e.what(), resolver::Where::at_file(log));
  }
  return ex;
}

/// The report's notes: the reader's, then what it skipped and counted.
std::vector<std::string> report_notes(const resolver::LogSamples& samples) { return resolver::input_notes(samples); }

/// fit or explain of two or more logs together.
int run_on_logs(const Arguments& a, const Model& model, const resolver::ProgressMeter::Options& shown) {
  resolver::PooledRun run;
  run.logs = a.logs;
  run.effects = model.effects;
  run.options = discovery_options(a, model.config);
  run.explain = a.command == Command::kExplain;
  run.json = a.json;
  run.jobs = a.jobs;
  if (a.command == Command::kReport) {
    run.html_out = a.html_out;
    run.max_steps = a.max_steps;
  }
  run.read = [&](const std::string& log, bool quiet) {
    Arguments one = a;
    one.log = log;
    return read_samples(one, model.config, quiet ? resolver::ProgressMeter::Options{} : shown);
  };
  run.weigh_faults = weigh_signal_faults;
  run.notes = report_notes;
  return resolver::run_pooled(run);
}

/// The log's statistics, whole or one run per chunk (--chunk S).
resolver::StatsFile statistics_of_log(const Arguments& a, const Model& model, const resolver::ProgressMeter::Options& shown,
                                      bool candidates = true, const resolver::FitStartValues& start = {}) {
  resolver::DiscoveryOptions options = discovery_options(a, model.config);
  options.statistics_candidates = candidates;
  options.start = start;
  resolver::StatsFile file = resolver::stats_file_header(a.log, model.config);
  std::function<void(resolver::DiscoveryInput&&)> on_chunk;
  if (a.chunk_s > 0.0) {
    on_chunk = [&](resolver::DiscoveryInput&& chunk) { resolver::add_chunk(file, chunk, model.effects, options); };
  }
  resolver::LogSamples samples = read_samples(a, model.config, shown, on_chunk);
  weigh_signal_faults(samples, options);
  try {
    if (!on_chunk) resolver::add_run(file, a.log, samples.input, model.effects, options);
  } catch (const std::invalid_argument& e) {
    throw resolver::InputError(resolver::Fault::kData, e.what(), resolver::Where::at_file(a.log));
  }
  if (file.runs.empty()) {
    throw resolver::InputError(resolver::Fault::kData,
                               fmt::format("no chunk of the log could be fitted: {} (each --chunk of {:g} s must hold "
                                           "the motion a fit needs: a longer chunk, or none, covers more)",
                                           fmt::join(file.left_out, "; "), a.chunk_s),
                               resolver::Where::at_file(a.log));
  }
  resolver::mark_untrusted(file, options.untrusted_input);
  file.input = resolver::input_notes(samples);
  return file;
}

/// stats: the file; fit or explain --chunk: its runs merged at once (a long log in the
/// memory of two chunks, reported as merge reports).
int run_stats(const Arguments& a, const Model& model, const resolver::ProgressMeter::Options& shown) {
  if (a.command == Command::kStats) {
    resolver::write_stats_file(statistics_of_log(a, model, shown), a.stats_out);
    return 0;
  }
  const std::vector<std::string> logs = a.logs.empty() ? std::vector<std::string>{a.log} : a.logs;
  // The first pass keeps every candidate's columns; a refit's only the model's.
  const auto statistics_with = [&](const std::vector<std::string>& effects, bool candidates,
                                    const resolver::FitStartValues& start) {
    Model with = model;
    with.effects = effects;
    std::vector<resolver::StatsFile> files;
    for (const std::string& log : logs) {
      Arguments one = a;
      one.log = log;
      files.push_back(statistics_of_log(one, with, shown, candidates, start));
    }
    return files;
  };
  const resolver::DiscoveryOptions options = discovery_options(a, model.config);
  resolver::MergedFiles merged = resolver::merge_files(statistics_with(model.effects, true, {}), logs, {}, options);
  // As a fit in memory: a nonlinear model is fitted to convergence and a candidate whose
  // linearised step is not its fit is refitted, here by further passes over the logs
  // (they are files: read again).
  const bool readable_again = std::all_of(logs.begin(), logs.end(), [](const std::string& l) {
    std::error_code ec;
    return std::filesystem::is_regular_file(l, ec);
  });
  if (readable_again) {
    resolver::relinearise_merge(merged, statistics_with, options);
    if (a.command == Command::kExplain) resolver::refit_from_logs(merged, statistics_with, options);
  } else {
    if (merged.fit.nonlinear && merged.runs.size() > 1) {
      merged.fit.notes.emplace_back("the model's nonlinear parameters are one linearised step from each run's own fit: "
                                    "a log is not a regular file and cannot be read a second time");
    }
    if (a.command == Command::kExplain && !resolver::candidates_to_refit(merged.fit, options).empty()) {
      merged.fit.notes.emplace_back("the candidates are not refitted: a log is not a regular file and cannot be read "
                                    "a second time (their scores are one linearised step)");
    }
    if (a.command == Command::kExplain) resolver::note_pairs_not_fitted(merged.fit);
  }
  resolver::print_merged(merged, a.json, options);
  return 0;
}

/// Every subcommand but fleet: read the log, then fit, explain or write.
int run_on_log(const Arguments& a) {
  const Model model = load_model(a);
  const resolver::ProgressMeter::Options shown = resolver::ProgressMeter::for_stderr(a.progress);
  if (a.command == Command::kStats || a.chunk_s > 0.0) return run_stats(a, model, shown);
  if (a.logs.size() > 1) return run_on_logs(a, model, shown);
  resolver::LogSamples samples = read_samples(a, model.config, shown);
  resolver::DiscoveryOptions options = discovery_options(a, model.config);
  weigh_signal_faults(samples, options);
  if (a.command == Command::kReport || a.command == Command::kExport || a.command == Command::kExportData) {
    return write_outputs(a, samples, model.effects, options, shown);
  }
  const bool do_explain = a.command == Command::kExplain;
  const resolver::Explanation ex = fit_or_explain(samples, a.log, model.effects, options, do_explain, shown);
  const std::vector<std::string> notes = report_notes(samples);
  std::cout << (a.json ? resolver::format_model_json(ex, do_explain, notes)
                       : resolver::format_model_text(ex, do_explain, notes));
  return 0;
}

int run(int argc, char** argv) {
  // The program's name, not argv[0] (a build path), in every usage line and man page.
  CLI::App app{"resolver-model: compare the effect model with a log, see where it fails, name the missing effect.",
               "resolver-model"};
  app.footer(std::string(kExamples) + "\n\n" + resolver::exit_code::kHelpText);
  app.require_subcommand(1);
  app.set_version_flag("--version", resolver::version_line("resolver-model"));
  Arguments a;
  Subcommands subs;
  add_discovery_subcommands(app, a, subs);
  add_calibration_subcommands(app, a, subs);
  if (auto code = resolver::exit_code::parse_command_line(app, argc, argv)) return *code;
  a.command = subs.parsed();
  if (!a.logs.empty()) a.log = a.logs.front();
  resolver::set_pass_threads(a.threads > 0 ? a.threads : static_cast<int>(std::thread::hardware_concurrency()));
  if (a.command == Command::kFleet) {
    return run_fleet(a.manifest, a.fleet_out, a.summarize_dir, split_effects(a.effects_args), a.config_path,
                     a.export_points, a.merge_only);
  }
  if (a.command == Command::kMerge) {
    for (const std::string& f : a.stats_files) resolver::exit_code::require_readable("STATS", f);  // IoError: exit 3
    const Model model = load_model(a);
    return resolver::run_merge(a.stats_files, split_effects(a.effects_args), a.json, discovery_options(a, model.config));
  }
  check_arguments(a);
  return run_on_log(a);
}

}  // namespace

// Every failure not answered above is an exception: the one rule of program_errors.h
// gives its exit code (a config error 2, no usable data 1, a failed write 3, out of memory 4).
int main(int argc, char** argv) {
  return resolver::run_program("resolver-model", [&] { return run(argc, argv); });
}
