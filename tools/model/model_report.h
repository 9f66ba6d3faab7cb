// Text and JSON renderings of a model-discovery result (resolver-model).
// JSON keys (issue 4): effects, params {name: {value, stderr}}, residual_rms_rad,
// noise_floor_rad, candidates [{effect, residual_after_rad, score, reason, ...}]
// best first, verdict; plus signals, harmonics, speed_bins, notes. A candidate's
// "one_step" is true when its values are one linearised step, not its fit (Candidate::stepped).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"

namespace resolver {

/// The text reports' line under a candidate whose values are one linearised step
/// (Candidate::stepped): only its fit with the model gives them exactly.
inline constexpr std::string_view kOneStepNote =
    "      values: one linearised step from zero, not its fit (approximate; fit it with the model for them)\n";

/// `explained` = false: the fit only (candidates and verdict omitted).
[[nodiscard]] std::string format_model_text(const Explanation& ex, bool explain, const std::vector<std::string>& notes);
/// `extra_members` (",\"key\":value...") ends the object (a pooled fit's "pool").
[[nodiscard]] std::string format_model_json(const Explanation& ex, bool explain, const std::vector<std::string>& notes,
                                            const std::string& extra_members = "");

}  // namespace resolver
