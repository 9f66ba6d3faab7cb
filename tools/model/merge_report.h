// Text and JSON of `resolver-model merge` (a fit from statistics files): the runs,
// the parameters, each signal's residual against the pooled floor, the candidates
// ranked from the same statistics and a verdict. The JSON keys follow fit's
// (model_report.h): effects, params {name: {value, stderr, unit}}, signals,
// candidates best first, verdict, notes; plus runs and nuisance.
#pragma once

#include <string>
#include <vector>

#include "daemon/core/discovery/run_statistics.h"

namespace resolver {

/// What the merge says in one word and one sentence.
struct MergeVerdict {
  std::string word;  ///< "explained", "missing_effect" or "unexplained"
  std::string summary;
};

[[nodiscard]] MergeVerdict merge_verdict(const MergedFit& m, double explained_ratio);

/// `runs`: the statistics files, in the order given.
[[nodiscard]] std::string format_merge_text(const MergedFit& m, const std::vector<std::string>& runs,
                                            const std::vector<RunStatistics>& stats, double explained_ratio);
[[nodiscard]] std::string format_merge_json(const MergedFit& m, const std::vector<std::string>& runs,
                                            const std::vector<RunStatistics>& stats, double explained_ratio);

}  // namespace resolver
