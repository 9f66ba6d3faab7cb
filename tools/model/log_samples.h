// A candump log of the default bench layout as model-discovery samples:
// CandumpReader -> FrameIntake (built-in DBC, SignalMap::bench_default) ->
// DiscoverySample per joined sample. p_r, p come from BENCH_INFO when the log
// has it (else the bench defaults, p_r = p = 3, and a note says so).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"

namespace resolver {

struct LogSamples {
  DiscoveryInput input;
  std::int64_t frames = 0;
  std::int64_t bad_lines = 0;
  std::int64_t problems = 0;       ///< decode problems (CRC, counters, ...)
  bool bench_info = false;
  std::vector<std::string> notes;  ///< what the log lacks
};

/// Reads `path`. progress(fraction of the file's bytes) is called now and then
/// (may be empty). Throws std::runtime_error "cannot open <path>: ..." when the
/// file cannot be read, and "<path>: no samples ..." when nothing decodes.
[[nodiscard]] LogSamples read_log_samples(const std::string& path, const std::function<void(double)>& progress);

}  // namespace resolver
