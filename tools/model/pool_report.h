// Text and JSON of a pooled fit's own part (resolver-model fit|explain A.log B.log ...):
// each log's residual in the pooled fit and each log's parameters fitted alone
// against the pool's, the disagreeing ones first. The pooled fit itself prints as
// any fit (model_report.h).
#pragma once

#include <string>
#include <vector>

#include "daemon/core/discovery/pool.h"

namespace resolver {

/// `names`: the logs in pool order; `fit`: the pooled fit (its parts); `logs`: each log's own fit.
[[nodiscard]] std::string format_pool_text(const std::vector<std::string>& names, const ModelFit& fit,
                                           const LogComparison& logs);
/// The "pool" member: `,"pool":{...}` (to end a fit's JSON object with).
[[nodiscard]] std::string format_pool_json(const std::vector<std::string>& names, const ModelFit& fit,
                                           const LogComparison& logs);

}  // namespace resolver
