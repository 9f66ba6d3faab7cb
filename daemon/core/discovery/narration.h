// Discovery in words: where the model fails (which signals, harmonics, speeds,
// directions, times, outliers), and, when nothing in the catalog explains the
// residual, a ready-to-paste [[model.custom]] block that describes it.
#pragma once

#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"

namespace resolver {

/// Sentences: each failing signal against its floor, the residual's harmonics,
/// its dependence on speed, direction and time, the outliers, the held-back
/// validation, a suspicious floor.
[[nodiscard]] std::vector<std::string> describe_failure(const PreparedLog& log, const ModelFit& fit, double ratio);

/// A [[model.custom]] block (TOML text) whose terms describe the position-error
/// residual: its significant orders of theta and theta_m, and how it depends on
/// speed, direction and time. The terms are chosen by fitting a dictionary of such
/// terms with the model and keeping the significant ones (> 4 standard errors).
/// Empty when there is nothing to describe. `name` names the block.
[[nodiscard]] std::string suggest_custom(const PreparedLog& log, const ModelFit& fit, const DiscoveryOptions& options,
                                         const std::string& name = "residual");

}  // namespace resolver
