#include "tools/model/stats_run.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "daemon/app/pipeline.h"
#include "daemon/core/errors.h"
#include "daemon/service/program_version.h"
#include "tools/model/html_report.h"
#include "tools/model/merge_report.h"

namespace resolver {

StatsFile stats_file_header(const std::string& log, const DaemonConfig& config) {
  StatsFile file;
  const LayoutIdentity layout = layout_identity(config);
  file.log = log;
  file.layout_id = layout.id;
  file.layout_description = layout.description;
  file.tool = version_line("resolver-model");
  return file;
}

void add_run(StatsFile& file, const std::string& name, const DiscoveryInput& input, std::span<const std::string> effects,
             const DiscoveryOptions& options) {
  const PreparedLog prepared = prepare_log(input, options.prepare);
  file.runs.push_back({name, run_statistics(prepared, effects, options)});
  if (!(file.amplitude > 0.0) && prepared.sincos) file.amplitude = prepared.amplitude;
  if (!std::isfinite(file.time_origin)) file.time_origin = prepared.time_origin;
}

void add_chunk(StatsFile& file, const DiscoveryInput& chunk, std::span<const std::string> effects,
               const DiscoveryOptions& options) {
  const double t0 = chunk.samples.front().t, t1 = chunk.samples.back().t;
  const std::string name = fmt::format("{} [{:.6g}-{:.6g} s]", file.log, t0, t1);
  DiscoveryOptions scaled = options;
  scaled.prepare.amplitude = file.amplitude;  // the first chunk's: one scale, one gain for the log
  scaled.prepare.time_origin = file.time_origin;  // and one time axis (a drift is one line)
  try {
    add_run(file, name, chunk, effects, scaled);
  } catch (const std::invalid_argument& e) {
    file.left_out.push_back(fmt::format("{}: {} samples left out: {}", name, chunk.samples.size(), e.what()));
  }
}

void mark_untrusted(StatsFile& file, const std::vector<std::string>& untrusted) {
  for (NamedRun& r : file.runs) r.run.untrusted = untrusted;
}

void write_stats_file(const StatsFile& file, const std::string& out) {
  const std::string text = format_stats_file(file);
  write_text_file(out, text);  // throws std::system_error: exit 3
  std::int64_t rows = 0;
  for (const NamedRun& r : file.runs) rows += r.run.fitted_rows;
  const RunStatistics& r = file.runs.front().run;
  std::cout << fmt::format("wrote {} ({} KiB): {} fitted samples of {} in {} run{}, model {}, {} columns ({} the "
                           "candidates')\n",
                           out, (text.size() + 512) / 1024, rows, file.log, file.runs.size(),
                           file.runs.size() == 1 ? "" : "s", fmt::join(r.effects, ","), r.columns.size(),
                           r.columns.size() - static_cast<std::size_t>(r.nuisance_columns + r.model_columns));
  for (const std::string& l : file.left_out) std::cout << "left out: " << l << "\n";
  for (const std::string& n : file.input) std::cout << "note: " << n << "\n";
}

int run_merge(const std::vector<std::string>& paths, std::span<const std::string> effects, bool json,
              const DiscoveryOptions& options) {
  std::vector<StatsFile> files;
  files.reserve(paths.size());
  for (const std::string& p : paths) files.push_back(read_stats_file(p));
  check_same_layout(files, paths);
  return print_merge(files, paths, effects, json, options);
}

MergedFiles merge_files(const std::vector<StatsFile>& files, const std::vector<std::string>& paths,
                        std::span<const std::string> effects, const DiscoveryOptions& options) {
  MergedFiles out;
  for (std::size_t i = 0; i < files.size(); ++i) {
    // A file of one run is named by its path; a chunked log's runs by path and span.
    for (const NamedRun& r : files[i].runs) {
      out.names.push_back(files[i].runs.size() == 1 ? paths[i]
                                                    : paths[i] + ": " + r.name.substr(r.name.rfind(" [") + 1));
      out.runs.push_back(r.run);
      out.log_of.push_back(static_cast<int>(i));  // a file's runs are one log's chunks: one reference zero
    }
  }
  try {
    out.fit = merge_runs(out.runs, out.names, effects, options, out.log_of);
  } catch (const std::invalid_argument& e) {
    throw InputError(Fault::kData, e.what());
  }
  for (const StatsFile& f : files) {
    for (const std::string& l : f.left_out) out.fit.notes.push_back("left out when the statistics were made: " + l);
    for (const std::string& n : f.input) out.fit.notes.push_back(f.log + ": " + n);
  }
  return out;
}

namespace {

/// Where the runs' refits with `effect` start: the merged model settled, the candidate at
/// its merged linearised step.
FitStartValues merged_start(const MergedFit& fit, const std::string& effect) {
  FitStartValues start;
  start.values = fit.params;
  start.settled = fit.effects;
  for (const Candidate& c : fit.candidates) {
    if (c.effect == effect) start.values.insert(start.values.end(), c.params.begin(), c.params.end());
  }
  return start;
}

/// Runs that hold the candidate (their rows alone cannot separate it) make the refit
/// Gauss-Newton over passes: each pass takes the statistics at the last merged value.
/// Converged when a pass moves each of its parameters by less than kConvergedSe of its
/// standard error; at most kMaxHeldPasses passes (each reads the logs again).
constexpr int kMaxHeldPasses = 6;
constexpr double kConvergedSe = 0.05;

/// The largest move of `effect`'s parameters from `start` to `with`, in standard errors.
double largest_step(const MergedFit& with, const FitStartValues& start, const std::string& effect,
                    const DiscoveryOptions& options) {
  const ModelTerm term = ModelSpec::parse(std::vector<std::string>{effect}, options.customs).terms.front();
  double widest = 0.0;
  for (std::size_t k = 0; k < term.params.size(); ++k) {
    const std::string name = term.param_name(k);
    const auto at = [&](const std::vector<ModelParameter>& ps) {
      return std::find_if(ps.begin(), ps.end(), [&](const ModelParameter& p) { return p.name == name; });
    };
    const auto now = at(with.params), before = at(start.values);
    if (now == with.params.end() || before == start.values.end() || !(now->std_error > 0.0)) continue;
    widest = std::max(widest, std::abs(now->value - before->value) / now->std_error);
  }
  return widest;
}

}  // namespace

void refit_from_logs(MergedFiles& merged, const StatisticsWith& statistics_with, const DiscoveryOptions& options) {
  for (const std::string& effect : candidates_to_refit(merged.fit, options)) {
    const auto not_refitted = [&](const std::string& why) {
      merged.fit.notes.push_back(fmt::format("{} not refitted (its score stays one linearised step): {}", effect, why));
    };
    std::vector<std::string> effects = merged.fit.effects;
    effects.push_back(effect);
    FitStartValues start = merged_start(merged.fit, effect);
    start.held = {effect};
    try {
      for (int pass = 1;; ++pass) {
        std::vector<RunStatistics> runs;
        for (const StatsFile& f : statistics_with(effects, start)) {
          for (const NamedRun& r : f.runs) runs.push_back(r.run);
        }
        if (runs.size() != merged.runs.size()) {
          not_refitted(fmt::format("{} of the {} runs could be fitted with it", runs.size(), merged.runs.size()));
          break;
        }
        MergedFit with = merge_runs(runs, merged.names, effects, options, merged.log_of);
        const bool held = std::any_of(runs.begin(), runs.end(), [](const RunStatistics& r) { return !r.held.empty(); });
        const double step = held ? largest_step(with, start, effect, options) : 0.0;
        if (held && step >= kConvergedSe && pass < kMaxHeldPasses) {
          start.values = with.params;
          continue;
        }
        if (held) {
          merged.fit.notes.push_back(fmt::format(
              "{}: some runs' rows alone cannot separate it (held at the merged value there): fitted by Gauss-Newton "
              "over {} pass{} of the logs, the last step {:.2g} standard errors{}",
              effect, pass, pass == 1 ? "" : "es", step, step < kConvergedSe ? "" : " (not converged: its value is approximate)"));
        }
        take_exact_refit(merged.fit, effect, with, options);
        break;
      }
    } catch (const std::invalid_argument& e) {
      not_refitted(e.what());
    } catch (const InputError& e) {
      not_refitted(e.what());
    }
  }
}

void print_merged(const MergedFiles& merged, bool json, const DiscoveryOptions& options) {
  std::cout << (json ? format_merge_json(merged.fit, merged.names, merged.runs, options.explained_ratio)
                     : format_merge_text(merged.fit, merged.names, merged.runs, options.explained_ratio));
}

int print_merge(const std::vector<StatsFile>& files, const std::vector<std::string>& paths,
                std::span<const std::string> effects, bool json, const DiscoveryOptions& options) {
  print_merged(merge_files(files, paths, effects, options), json, options);
  return 0;
}

}  // namespace resolver
