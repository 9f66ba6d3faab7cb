// resolver-model stats LOG --out FILE.stats and merge A.stats B.stats ... (issue 24):
// a log's statistics written once, fits of many runs made from them without the logs.
#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>

#include "daemon/app/daemon_config.h"
#include "daemon/core/discovery/model_discovery.h"
#include "tools/model/log_samples.h"
#include "tools/model/stats_file.h"

namespace resolver {

/// A file without runs yet: the log, the layout of `config`, this program's version.
[[nodiscard]] StatsFile stats_file_header(const std::string& log, const DaemonConfig& config);

/// Prepares `input`, fits `effects` and takes the statistics pass (run_statistics.h)
/// into `file` as a run named `name`. Throws std::invalid_argument when the fit
/// refuses the samples (too few, the rotor hardly moves, ...).
void add_run(StatsFile& file, const std::string& name, const DiscoveryInput& input, std::span<const std::string> effects,
             const DiscoveryOptions& options);

/// add_run for one chunk of a long log (LogReadOptions::on_chunk), named "LOG [t0-t1 s]";
/// a chunk the fit refuses is counted in file.left_out with its span and reason.
void add_chunk(StatsFile& file, const DiscoveryInput& chunk, std::span<const std::string> effects,
               const DiscoveryOptions& options);

/// Marks every run with the log's lasting signal faults (a merge is then never "explained").
void mark_untrusted(StatsFile& file, const std::vector<std::string>& untrusted);

/// Writes `file` to `out` (IoError: exit 3) and says what it holds on stdout.
void write_stats_file(const StatsFile& file, const std::string& out);

/// The runs of several statistics files, merged.
struct MergedFiles {
  std::vector<std::string> paths;  ///< the files (or logs) merged, as given
  std::vector<RunStatistics> runs;
  std::vector<std::string> names;  ///< a file's path; a chunk's with its span
  std::vector<int> log_of;         ///< each run's file: the runs of one file are one log's chunks
  /// What the files say of themselves (chunks left out, input notes): every merge of them notes it.
  std::vector<std::string> file_notes;
  MergedFit fit;
};

/// Merges the runs of `files` (named by `paths`, a chunk by its span too) with `effects`
/// (empty: the first run's model); what the statistics left out goes into the notes.
/// InputError (data) when they do not merge. The runs are moved out of `files`.
[[nodiscard]] MergedFiles merge_files(std::vector<StatsFile> files, const std::vector<std::string>& paths,
                                      std::span<const std::string> effects, const DiscoveryOptions& options);

/// The runs of `merged` merged again with `effects`, the model's step damped by `lambda`
/// (merge_runs), with the files' notes. InputError (data) when they do not merge.
[[nodiscard]] MergedFit merge_again(const MergedFiles& merged, std::span<const std::string> effects,
                                    const DiscoveryOptions& options, double lambda = 0.0);

/// The same logs' statistics made again with the model `effects` (with every candidate's
/// columns or only the model's), each run's fit started at `start` (one file per log, the
/// runs in the same order): a further pass over the logs.
using StatisticsWith = std::function<std::vector<StatsFile>(const std::vector<std::string>& effects, bool candidates,
                                                            const FitStartValues& start)>;

/// Gauss-Newton over passes for a nonlinear model (MergedFit::nonlinear) of several runs:
/// the merge moves each run's statistics linearly from its own fit to the merged point,
/// exact only to second order in how far apart those lie (a 50 mrad mounting offset
/// turning the currents put theta_0 11 standard errors from the fit in memory). Each pass
/// makes every run's statistics again at the last merged fit (FitStartValues::at_start)
/// and merges them, until a pass moves every model parameter by < 0.05 standard errors
/// (at most 6 passes); the candidates are ranked at that point. A note says how many.
void relinearise_merge(MergedFiles& merged, const StatisticsWith& statistics_with, const DiscoveryOptions& options);

/// explain on statistics, as on a log in memory: each candidate whose linearised step is
/// not its fit (candidates_to_refit) is refitted to convergence by making the statistics
/// again with it in the model, and scored by that merge (take_exact_refit). Each run's
/// refit starts at the merged fit: the model's values settled, the candidate's from its
/// merged linearised step (with its own other starts), as the in-memory refit starts at
/// the model's converged fit. A nonlinear refit of several runs, or one some run holds
/// (its rows alone cannot separate it), is then relinearised at the merged fit over
/// passes as relinearise_merge. A refit that fails leaves the candidate linearised, with
/// a note saying why. Then, where the best candidate does not reach the floor, explain's
/// two-effect search on the merged statistics: the pairs whose joint linearised step fits
/// best (MergedFit::screened_pairs; at most 3, 1 where the best alone removes most of the
/// excess) fitted so, the first whose merge is explained named (MergedFit::missing_pair).
void refit_from_logs(MergedFiles& merged, const StatisticsWith& statistics_with, const DiscoveryOptions& options);

/// Where explain's two-effect search would run on `m` (refit_from_logs) but cannot (no logs
/// to read again): a note naming the pair the screen puts first.
void note_pairs_not_fitted(MergedFit& m);

/// Prints `merged` as text or JSON on stdout.
void print_merged(const MergedFiles& merged, bool json, const DiscoveryOptions& options);

/// merge_files, then print_merged; returns 0.
int print_merge(const std::vector<StatsFile>& files, const std::vector<std::string>& paths,
                std::span<const std::string> effects, bool json, const DiscoveryOptions& options);

/// Reads the statistics files, checks they are of one layout and merges them with
/// `effects` (empty: the first run's model); prints text or JSON on stdout; returns 0.
int run_merge(const std::vector<std::string>& paths, std::span<const std::string> effects, bool json,
              const DiscoveryOptions& options);

}  // namespace resolver
