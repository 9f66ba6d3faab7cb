// The statistics file of `resolver-model stats` (issue 24): one run's statistics
// (daemon/core/discovery/run_statistics.h) as self-describing JSON that `merge`
// reads back exactly (every double with 17 significant digits).
//
//   {"format": "resolver-model stats", "version": 2, "tool": "resolver-model ...",
//    "log": ..., "layout": {"id", "description"}, "left_out": [...], "input": [...],
//    "runs": [{"name": ..., "bench": {"p_r", "p"}, "signals": {...}, "effects": [...],
//              "params": [...], "values": [[...]], "frame_shift": ..., "columns": [...],
//              "candidate_sets": ["harmonics(k5)", ...],
//              "nuisance_columns": n, "model_columns": m, "point": [...],
//              "floors": {"rd": {...}, "sc": {...}, "cur": {...}}, "counts": {...},
//              "motion": {...}, "notes": [...], "untrusted": [...],
//              "outliers": {"samples", "rows": [per group], "rss": [per group]},
//              "groups": {"rd": {"all": {"n", "yy", "b", "m_upper"}, "fold_a": {...}}, "sc": ..., "cur": ...}}]}
// One run per log, or one per chunk of a long log (stats --chunk): each chunk is a run
// with its own constants, so a log of any length is read in bounded memory; a merge
// shares the log's reference zero across the runs of one file (run_statistics.h).
//
// A file of another format or version, or one that does not parse, is refused naming
// the file (InputError, usage: exit 2); so are files of different layouts in one merge.
// Version 2 added the outliers a run's fit left out (a merge is not explained where
// they carry a signal above its floor) and the harmonic orders its residual asks for
// (candidate_sets): a version 1 file lacks them, so it is made again.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "daemon/core/discovery/run_statistics.h"

namespace resolver {

/// 3: a log's chunks are normalised by its first chunk's amplitude and timed from its origin
/// (a merge shares their gain and clock): version 2 chunks had their own.
inline constexpr int kStatsFileVersion = 3;

/// One run of a file: its name (the log, or "LOG [t0-t1 s]" for a chunk) and statistics.
struct NamedRun {
  std::string name;
  RunStatistics run;
};

/// A statistics file's content: its runs and where they came from.
struct StatsFile {
  std::vector<NamedRun> runs;
  std::string log;                 ///< the log it was made from, as given
  std::string layout_id;           ///< the layout's identity (pipeline.h layout_identity)
  std::string layout_description;  ///< in words, for messages
  std::string tool;                ///< the version line of the program that wrote it
  /// Chunks of the log no fit could be made of, each with its time span and reason.
  std::vector<std::string> left_out;
  /// What the reader said and counted (log_samples.h input_notes): malformed lines,
  /// input problems, what the log lacks; a merge prints them.
  std::vector<std::string> input;
  /// [counts] the first run's envelope amplitude: a later chunk is normalised by it
  /// (PrepareOptions::amplitude; not written: a pass over the log finds it again).
  double amplitude = 0.0;
  /// [s] the first run's time origin (PrepareOptions::time_origin), likewise.
  double time_origin = std::numeric_limits<double>::quiet_NaN();
  /// Where the last chunk read left the rotor (PrepareOptions::continuation): the next
  /// chunk goes on from it, as the whole log does (not written either).
  MotionContinuation continuation;
};

/// The file's text.
[[nodiscard]] std::string format_stats_file(const StatsFile& file);

/// Parses `text` read from `path`. Throws InputError (usage, naming `path`) when it is
/// not a statistics file of this version or a member is missing or malformed.
[[nodiscard]] StatsFile parse_stats_file(const std::string& text, const std::string& path);

/// Reads and parses `path` (IoError when it cannot be read).
[[nodiscard]] StatsFile read_stats_file(const std::string& path);

/// Throws InputError (usage) naming both files when `files` were made with different
/// layouts (the signals mean other things).
void check_same_layout(const std::vector<StatsFile>& files, const std::vector<std::string>& paths);

}  // namespace resolver
