// The simulator's ground truth as JSON: the configuration and every effect
// parameter a log was generated with, for tests and reports to compare against.
#pragma once

#include <string>

#include "tools/sim/bench_simulator.h"

namespace resolver {

/// JSON object: run settings, speed profile, "effects" (active effects and their
/// parameters, catalog names) and "chain" (every implemented effect's parameters,
/// active or not). `log_path` is recorded as given. Cannot fail.
[[nodiscard]] std::string sim_truth_json(const SimConfig& config, std::uint64_t total_samples,
                                         const std::string& log_path);

}  // namespace resolver
