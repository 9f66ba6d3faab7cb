#include "tools/model/stats_run.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>
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
  file.continuation = prepared.continuation;
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
  // And the rotor's state where the last chunk left it (a play's take-up, the direction
  // held through a standstill). A chunk that cannot be prepared (one that hardly moves)
  // leaves it as it was.
  scaled.prepare.continuation = file.continuation;
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

MergedFiles merge_files(std::vector<StatsFile> files, const std::vector<std::string>& paths,
                        std::span<const std::string> effects, const DiscoveryOptions& options) {
  MergedFiles out;
  out.paths = paths;
  for (std::size_t i = 0; i < files.size(); ++i) {
    // A file of one run is named by its path; a chunked log's runs by path and span.
    for (NamedRun& r : files[i].runs) {
      out.names.push_back(files[i].runs.size() == 1 ? paths[i]
                                                    : paths[i] + ": " + r.name.substr(r.name.rfind(" [") + 1));
      out.runs.push_back(std::move(r.run));  // moved: a pass over a long log holds its runs' statistics once
      out.log_of.push_back(static_cast<int>(i));  // a file's runs are one log's chunks: one reference zero
    }
  }
  for (const StatsFile& f : files) {
    for (const std::string& l : f.left_out) out.file_notes.push_back("left out when the statistics were made: " + l);
    for (const std::string& n : f.input) out.file_notes.push_back(f.log + ": " + n);
  }
  out.fit = merge_again(out, effects, options);
  return out;
}

MergedFit merge_again(const MergedFiles& merged, std::span<const std::string> effects, const DiscoveryOptions& options,
                      double lambda) {
  MergedFit fit;
  try {
    fit = merge_runs(merged.runs, merged.names, effects, options, merged.log_of, lambda);
  } catch (const std::invalid_argument& e) {
    throw InputError(Fault::kData, e.what());
  }
  fit.notes.insert(fit.notes.end(), merged.file_notes.begin(), merged.file_notes.end());
  return fit;
}

namespace {

/// Where the runs' refits with `added` start: the merged model settled, each candidate at
/// its merged linearised step.
FitStartValues merged_start(const MergedFit& fit, const std::vector<std::string>& added) {
  FitStartValues start;
  start.values = fit.params;
  start.settled = fit.effects;
  for (const Candidate& c : fit.candidates) {
    if (std::find(added.begin(), added.end(), c.effect) != added.end()) {
      start.values.insert(start.values.end(), c.params.begin(), c.params.end());
    }
  }
  return start;
}

/// Gauss-Newton over passes of the logs (relinearise_merge, refit_from_logs): converged
/// when a pass moves each parameter by less than kConvergedSe of its standard error; at
/// most kMaxPasses passes (each reads the logs again).
constexpr int kMaxPasses = 6;
constexpr double kConvergedSe = 0.05;

/// The largest move of a parameter from `before` to `now`, in `now`'s standard errors.
double largest_step(const std::vector<ModelParameter>& now, const std::vector<ModelParameter>& before) {
  double widest = 0.0;
  for (const ModelParameter& p : now) {
    const auto was = std::find_if(before.begin(), before.end(), [&](const ModelParameter& q) { return q.name == p.name; });
    if (was == before.end() || !(p.std_error > 0.0)) continue;
    widest = std::max(widest, std::abs(p.value - was->value) / p.std_error);
  }
  return widest;
}

/// What the passes of iterate_at_merged did.
struct Passes {
  int passes = 0;
  double first = 0.0;  ///< [se] the first pass's step
  double last = 0.0;   ///< [se] the last good pass's step
  int accepted = 0;    ///< passes whose point was taken
  std::string failed;  ///< why a pass could not be made or merged (the last good merge stands)
  bool uphill = false;  ///< ended at the last good point: a step and its damped retry both went uphill
};

/// "over 3 passes of the logs, the first step 1.6 standard errors, the last 0.01".
std::string passes_note(const Passes& p) {
  const std::string passes = fmt::format("{} pass{} of the logs", p.passes, p.passes == 1 ? "" : "es");
  if (!p.failed.empty()) {
    return fmt::format("stopped after {}: {} (the last good merge is kept: approximate)", passes, p.failed);
  }
  if (p.uphill && p.accepted == 0) {
    return fmt::format("over {}: the merged point fitted the rows worse than the one step from the runs' own fits "
                       "said, damped too, so that step is kept (approximate: a parameter at a bound of its range, "
                       "e.g. an ideal converter, does this)",
                       passes);
  }
  if (p.uphill) {
    return fmt::format("over {}: a step went uphill, damped too, so the last good merge is kept, its step {:.2g} "
                       "standard errors (not converged: the values are approximate)",
                       passes, p.last);
  }
  return fmt::format("over {}, the first step {:.2g} standard errors, the last {:.2g}{}", passes, p.first, p.last,
                     p.last < kConvergedSe ? "" : " (not converged: the values are approximate)");
}

/// Gauss-Newton over passes from `at` (a merge of `effects`): each pass makes every run's
/// statistics at the last merged fit (FitStartValues::at_start) and merges them; that
/// merge's step from its point is undamped, so converged when it is < kConvergedSe. As
/// the fit in memory (least_squares.cpp fit_from_start), a point whose cost is higher
/// than the last good one's is not taken: the step from the good point is damped once
/// (Levenberg-Marquardt, from its statistics: no pass), and when that goes uphill too
/// the last good merge is the answer. `at`'s own cost is at its reference run's point,
/// exact to second order in how far its runs' own fits lie apart. (Undamped, a tracking
/// loop that every chunk fits at its bound, an ideal converter, swung between omega_n = 0
/// and 5000 rad/s over six passes.) Ends with `at` the last good merge.
Passes iterate_at_merged(MergedFiles& at, const std::vector<std::string>& effects, bool candidates, FitStartValues start,
                         const StatisticsWith& statistics_with, const DiscoveryOptions& options) {
  start.at_start = true;
  Passes out;
  std::optional<MergedFiles> good;  // the last pass taken
  double good_cost = at.fit.cost_at_point;
  std::vector<ModelParameter> next = at.fit.params;  // the next pass's point
  double lambda = 0.0;
  while (out.passes < kMaxPasses) {
    start.values = next;
    std::optional<MergedFiles> made;
    try {
      made = merge_files(statistics_with(effects, candidates, start), at.paths, effects, options);
    } catch (const InputError& e) {
      out.failed = e.what();  // a chunk that no longer fits there, say: the last good merge stands
      break;
    }
    MergedFiles& here = *made;
    ++out.passes;
    const double step = largest_step(here.fit.params, start.values);
    if (out.passes == 1) out.first = step;
    // Rounding in sums over many rows: a rise below 1e-9 relative is not a worse point.
    if (here.fit.cost_at_point > good_cost + 1e-9 * good_cost + 1e-6) {
      if (lambda > 0.0) {
        out.uphill = true;
        break;
      }
      lambda = 1e-4;  // fit_from_start's first damped step (1e-3, then /10 before it is taken)
      next = merge_again(good ? *good : at, effects, options, lambda).params;
      continue;
    }
    good = std::move(here);
    good_cost = good->fit.cost_at_point;
    out.last = step;
    ++out.accepted;
    at.runs = {};  // superseded: a long log's runs are held twice at most (the last good pass, the next)
    lambda = 0.0;
    if (step < kConvergedSe) break;
    next = good->fit.params;
  }
  if (good) at = std::move(*good);
  return out;
}

/// True when the merge of a nonlinear model is not exact enough as one step from the
/// runs' own fits: a move that changes a run's signals by delta floors per row
/// (MergedFit::run_move) leaves second-order terms of at most delta^2 / A floors per row,
/// A the effect's nonlinearity scale in floors (an envelope effect's is the unit
/// amplitude, ~1e4 floors; taken as 1 here, the most nonlinear any fitted effect is); a
/// systematic error of e floors per row moves a parameter by at most e sqrt(N) standard
/// errors over N rows. So one step is enough while delta^2 sqrt(N) < kConvergedSe:
/// measured 0.0013 floors on a 600 r/min log in 10 s chunks (three runs) against 155 where
/// a 50 mrad mounting offset the model lacks turns the currents.
bool needs_passes(const MergedFit& m, std::size_t runs) {
  if (!m.nonlinear || runs < 2) return false;
  return m.run_move * m.run_move * std::sqrt(static_cast<double>(m.rows)) >= kConvergedSe;
}

}  // namespace

void relinearise_merge(MergedFiles& merged, const StatisticsWith& statistics_with, const DiscoveryOptions& options) {
  if (!merged.fit.nonlinear || merged.runs.size() < 2) return;
  if (!needs_passes(merged.fit, merged.runs.size())) {
    merged.fit.notes.push_back(fmt::format("the model is nonlinear: its merge is one step from each run's own fit, "
                                           "which lie within {:.2g} floors of it (second order: < {} standard errors)",
                                           merged.fit.run_move, kConvergedSe));
    return;
  }
  const std::vector<std::string> effects = merged.fit.effects;
  FitStartValues start;
  start.settled = effects;
  const Passes p = iterate_at_merged(merged, effects, true, start, statistics_with, options);
  merged.fit.notes.push_back("the model is nonlinear: Gauss-Newton with every run's statistics made again at the "
                             "merged fit " + passes_note(p));
}

namespace {

/// The merge with `added` candidates in the model, fitted exactly (merge_exactly).
struct ExactMerge {
  std::optional<MergedFiles> with;  ///< empty: not fitted, `why` says why
  std::string why;
  std::string passes;  ///< what Gauss-Newton over passes did; empty when one pass is the fit
  bool held = false;   ///< some run's rows alone could not separate an added one
};

/// The logs' statistics made again with `added` in the model, each run's fit started at the
/// merged fit (merged_start), and merged: the exact fit for a linear model or a single run.
/// A nonlinear one of several runs, or one some run holds, is relinearised at the merged
/// fit over passes (iterate_at_merged).
ExactMerge merge_exactly(const MergedFiles& merged, const std::vector<std::string>& added,
                         const StatisticsWith& statistics_with, const DiscoveryOptions& options) {
  ExactMerge out;
  std::vector<std::string> effects = merged.fit.effects;
  effects.insert(effects.end(), added.begin(), added.end());
  FitStartValues start = merged_start(merged.fit, added);
  start.held = added;
  try {
    // The first pass fits each run from the merged start (its own valley of the
    // candidate); their merge is the fit only for a linear model or a single run.
    MergedFiles with = merge_files(statistics_with(effects, false, start), merged.paths, effects, options);
    if (with.runs.size() != merged.runs.size()) {
      out.why = fmt::format("{} of the {} runs could be fitted with {}", with.runs.size(), merged.runs.size(),
                            fmt::join(added, " and "));
      return out;
    }
    out.held = std::any_of(with.runs.begin(), with.runs.end(), [](const RunStatistics& r) { return !r.held.empty(); });
    if (out.held || needs_passes(with.fit, with.runs.size())) {
      out.passes = passes_note(iterate_at_merged(with, effects, false, start, statistics_with, options));
    }
    out.with = std::move(with);
  } catch (const std::invalid_argument& e) {
    out.why = e.what();
  } catch (const InputError& e) {
    out.why = e.what();
  }
  return out;
}

/// Whether explain's two-effect search runs on `m`, and which: where its best candidate does
/// not reach the floor (model_discovery.cpp), only the screen's first pairs where it removes
/// most of the excess (named already). None where the merge is explained or not judged.
std::optional<PairSearch> pair_search_of(const MergedFit& m) {
  if (m.explained || m.untrusted || !m.linearised.empty() || m.candidates.empty()) return std::nullopt;
  const Candidate& best = m.candidates.front();
  if (!best.proposed || best.reaches_floor || m.screened_pairs.empty()) return std::nullopt;
  std::int64_t rows = 0;
  for (const SignalResidual& r : m.signals) rows += r.rows;
  return removes_most_excess(m.signals, rows, m.rd, best.weighted_rss) ? PairSearch::kScreened : PairSearch::kEvery;
}

/// explain in memory's two-effect search (model_discovery.cpp, ranking.h find_missing_pair)
/// on the merged statistics: where the best candidate does not reach the floor, the pairs
/// whose joint linearised step fits best (MergedFit::screened_pairs) are fitted exactly, and
/// the first whose merge is explained is the finding. Only the screened pairs: the search
/// in memory tries the best three and classes of alike candidates first, which a pass
/// over the logs per pair makes dear here.
void find_missing_pair_from_logs(MergedFiles& merged, const StatisticsWith& statistics_with,
                                 const DiscoveryOptions& options) {
  MergedFit& m = merged.fit;
  const std::optional<PairSearch> search = pair_search_of(m);
  if (!search) return;
  const std::vector<ScreenedPair>& screened = m.screened_pairs;  // the search adds only notes and the pair
  int fits = 0;
  for (const ScreenedPair& pair : screened) {
    if (!fits_next_screened(fits, *search, pair.weighted_rss, screened.front().weighted_rss)) break;
    ++fits;
    const std::string& a = pair.a;
    const std::string& b = pair.b;
    ExactMerge e = merge_exactly(merged, {a, b}, statistics_with, options);
    if (!e.with) {
      m.notes.push_back(fmt::format("the pair {} and {} was not fitted: {}", a, b, e.why));
      continue;
    }
    if (!e.with->fit.explained) continue;
    m.missing_pair = {a, b};
    for (const ModelParameter& p : e.with->fit.params) {
      const bool model_param = std::any_of(m.params.begin(), m.params.end(),
                                           [&](const ModelParameter& q) { return q.name == p.name; });
      if (!model_param) m.missing_pair_params.push_back(p);
    }
    if (!e.passes.empty()) {
      m.notes.push_back(fmt::format("{} and {}: Gauss-Newton with every run's statistics made again at the merged fit "
                                    "with both {}", a, b, e.passes));
    }
    return;
  }
}

}  // namespace

void note_pairs_not_fitted(MergedFit& m) {
  if (!pair_search_of(m)) return;
  m.pair_search_skipped = true;
  const ScreenedPair& first = m.screened_pairs.front();
  m.notes.push_back(fmt::format("no candidate alone reaches the floor and two together may ({} and {} fit best "
                                "together, linearised): pairs are fitted only over passes of the logs, which these "
                                "are not (statistics files, or a log that is not a regular file); run "
                                "resolver-model explain --chunk on the logs",
                                first.a, first.b));
}

void refit_from_logs(MergedFiles& merged, const StatisticsWith& statistics_with, const DiscoveryOptions& options) {
  for (const std::string& effect : candidates_to_refit(merged.fit, options)) {
    const ExactMerge e = merge_exactly(merged, {effect}, statistics_with, options);
    if (!e.with) {
      merged.fit.notes.push_back(fmt::format("{} not refitted (its score stays one linearised step): {}", effect, e.why));
      continue;
    }
    if (!e.passes.empty()) {
      merged.fit.notes.push_back(fmt::format(
          "{}: Gauss-Newton with every run's statistics made again at the merged fit with it{} {}", effect,
          e.held ? " (some runs' rows alone cannot separate it: held at the merged value there)" : "", e.passes));
    }
    take_exact_refit(merged.fit, effect, e.with->fit, options);
  }
  find_missing_pair_from_logs(merged, statistics_with, options);
}

void print_merged(const MergedFiles& merged, bool json, const DiscoveryOptions& options) {
  std::cout << (json ? format_merge_json(merged.fit, merged.names, merged.runs, options.explained_ratio)
                     : format_merge_text(merged.fit, merged.names, merged.runs, options.explained_ratio));
}

int print_merge(const std::vector<StatsFile>& files, const std::vector<std::string>& paths,
                std::span<const std::string> effects, bool json, const DiscoveryOptions& options) {
  MergedFiles merged = merge_files(files, paths, effects, options);
  note_pairs_not_fitted(merged.fit);
  print_merged(merged, json, options);
  return 0;
}

}  // namespace resolver
