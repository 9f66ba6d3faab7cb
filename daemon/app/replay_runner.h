// Replays a log (candump -l, Vector ASC or CSV: log_input.h) through the
// pipeline: in the log's own timing (frame i is fed at t0 + (ts_i - ts_0);
// a stamp that steps back or jumps by more than kMaxPacedGapUs re-anchors the
// pacing instead of waiting) or as fast as possible, once or in a loop.
// Malformed lines are counted and reported with file:line:column.
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>

#include "daemon/app/log_format.h"
#include "daemon/app/pipeline.h"
#include "daemon/app/stop_flag.h"

namespace resolver {

/// Fast replay measures the read -> publish latency of one frame in this many.
inline constexpr std::uint64_t kReplayLatencyEvery = 16;

/// [us] longest pause paced replay reproduces; a longer one (an outage, a clock
/// jump, a second log appended) is not waited for.
inline constexpr std::int64_t kMaxPacedGapUs = 1'000'000;

struct ReplayOptions {
  std::string path;
  std::optional<LogFormat> format;  ///< --format; nullopt: [input] format, else the extension
  bool fast = false;   ///< ignore log timing
  bool once = true;    ///< stop at the end of the log (else loop)
  bool progress = true;  ///< progress lines on stderr for long runs
};

struct ReplayResult {
  std::uint64_t frames = 0;
  std::uint64_t bad_lines = 0;
  std::uint64_t passes = 0;
  double wall_seconds = 0.0;
};

/// Runs until the end of the log (once), past the pipeline's slice, or until
/// flags.stop. Throws std::runtime_error when the log cannot be opened and
/// ConfigError when a CSV's column map does not fit it.
ReplayResult run_replay(const ReplayOptions& options, Pipeline& pipeline, StopFlags& flags, std::ostream& err);

}  // namespace resolver
