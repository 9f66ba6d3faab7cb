// Replays a log (candump -l, Vector ASC or CSV: log_input.h) through the
// pipeline: in the log's own timing (frame i is fed at t0 + (ts_i - ts_0) / rate;
// a stamp that steps back or jumps by more than kMaxPacedGapUs re-anchors the
// pacing instead of waiting) or as fast as possible, once or in a loop.
// Malformed lines are counted and reported with file:line:column.
//
// A loop is one continuous bench run to everything downstream: each pass's
// frame times are shifted by the log's span (plus one frame interval) per pass,
// so utime and the health_t period keep counting up. A FIFO, pipe or device is
// read once (its data is gone once read): the loop stops after one pass, saying
// so. A file that shrank while it was read throws IoError; one that grew is read
// to the end met, with a warning. SIGINT/SIGTERM end the
// replay within LineReader::kStopPollMs on any input (a pause in the log's
// timing is slept in slices); SIGHUP rebuilds the pipeline from the config
// between two frames, as live.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>

#include "daemon/app/log_format.h"
#include "daemon/app/pipeline.h"
#include "daemon/app/stop_flag.h"

namespace resolver {

/// [us] longest pause paced replay reproduces; a longer one (an outage, a clock
/// jump, a second log appended) is not waited for.
inline constexpr std::int64_t kMaxPacedGapUs = 1'000'000;

/// Fast replay measures the read -> publish latency of one frame in this many.
inline constexpr std::uint64_t kReplayLatencyEvery = 16;

struct ReplayOptions {
  std::string path;
  bool fast = false;   ///< ignore log timing
  bool once = true;    ///< stop at the end of the log (else loop)
  bool progress = true;  ///< progress on stderr for long runs (a terminal: one line, 4x/s; else every 2 s)
  double rate = 1.0;   ///< paced replay at this many times the log's speed (> 0; not with fast)
  std::optional<LogFormat> format;  ///< --format; nullopt: [input] format, else the extension
};

struct ReplayResult {
  std::uint64_t frames = 0;
  std::uint64_t bad_lines = 0;
  std::uint64_t passes = 0;
  double wall_seconds = 0.0;
};

/// Runs until the end of the log (once), past the pipeline's slice, or until
/// flags.stop. `current` is the pipeline to feed; `on_reload` is called between
/// frames when flags.reload is set and may replace it (the old one is finished by
/// on_reload). Throws std::system_error when the log cannot be opened or read or
/// shrank while it was read, and ConfigError when a CSV's column map does not fit it.
ReplayResult run_replay(const ReplayOptions& options, const std::function<Pipeline&()>& current,
                        const std::function<void()>& on_reload, StopFlags& flags, std::ostream& err);
/// The same with one pipeline and SIGHUP ignored.
ReplayResult run_replay(const ReplayOptions& options, Pipeline& pipeline, StopFlags& flags, std::ostream& err);

}  // namespace resolver
