// A candump log as model-discovery samples: CandumpReader -> FrameIntake (the
// resolverd config's DBC and signal map: by default the built-in DBC and the
// default bench layout) -> DiscoverySample per joined sample. p_r, p come from
// BENCH_INFO when the log has it (unless the config says use_bench_info = false),
// else the config's [bench] values, and a note says so.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "daemon/app/daemon_config.h"
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
/// file cannot be read, "<path>: no samples ..." when nothing decodes, and
/// ConfigError when the config's DBC or signal map is bad.
[[nodiscard]] LogSamples read_log_samples(const std::string& path, const std::function<void(double)>& progress,
                                          const DaemonConfig& config = DaemonConfig{});

}  // namespace resolver
