// Replays a candump -l log through the pipeline: in the log's own timing
// (frame i is fed at t0 + (ts_i - ts_0) / rate) or as fast as possible, once or
// in a loop. Malformed lines are counted and reported with file:line:column.
//
// A loop is one continuous bench run to everything downstream: each pass's
// frame times are shifted by the log's span (plus one frame interval) per pass,
// so utime and the health_t period keep counting up. SIGINT/SIGTERM end the
// replay within CandumpReader::kStopPollMs on any input (a pause in the log's
// timing is slept in slices); SIGHUP rebuilds the pipeline from the config
// between two frames, as live.
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>

#include "daemon/app/pipeline.h"
#include "daemon/app/stop_flag.h"

namespace resolver {

/// Fast replay measures the read -> publish latency of one frame in this many.
inline constexpr std::uint64_t kReplayLatencyEvery = 16;

struct ReplayOptions {
  std::string path;
  bool fast = false;   ///< ignore log timing
  bool once = true;    ///< stop at the end of the log (else loop)
  bool progress = true;  ///< progress lines on stderr for long runs
  double rate = 1.0;   ///< paced replay at this many times the log's speed (> 0; not with fast)
};

struct ReplayResult {
  std::uint64_t frames = 0;
  std::uint64_t bad_lines = 0;
  std::uint64_t passes = 0;
  double wall_seconds = 0.0;
};

/// Runs until the end of the log (once) or until flags.stop. `current` is the
/// pipeline to feed; `on_reload` is called between frames when flags.reload is
/// set and may replace it (the old one is finished by on_reload). Throws
/// std::runtime_error when the log cannot be opened or read.
ReplayResult run_replay(const ReplayOptions& options, const std::function<Pipeline&()>& current,
                        const std::function<void()>& on_reload, StopFlags& flags, std::ostream& err);
/// The same with one pipeline and SIGHUP ignored.
ReplayResult run_replay(const ReplayOptions& options, Pipeline& pipeline, StopFlags& flags, std::ostream& err);

}  // namespace resolver
