// resolver-model stats LOG --out FILE.stats and merge A.stats B.stats ... (issue 24):
// a log's statistics written once, fits of many runs made from them without the logs.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "daemon/app/daemon_config.h"
#include "daemon/core/discovery/model_discovery.h"
#include "tools/model/log_samples.h"
#include "tools/model/stats_file.h"

namespace resolver {

/// Prepares the log's samples, fits `effects` and takes the statistics pass
/// (run_statistics.h) with the layout of `config` recorded. Throws InputError (data,
/// naming `log`) when the fit refuses the samples.
[[nodiscard]] StatsFile make_stats_file(const LogSamples& samples, const std::string& log,
                                        std::span<const std::string> effects, const DiscoveryOptions& options,
                                        const DaemonConfig& config);

/// Writes `file` to `out` (IoError: exit 3) and says what it holds on stdout.
void write_stats_file(const StatsFile& file, const std::string& out);

/// Reads the statistics files, checks they are of one layout and merges them with
/// `effects` (empty: the first run's model); prints text or JSON on stdout; returns 0.
int run_merge(const std::vector<std::string>& paths, std::span<const std::string> effects, bool json,
              const DiscoveryOptions& options);

}  // namespace resolver
