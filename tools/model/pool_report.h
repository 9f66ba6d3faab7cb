// Text and JSON of a pooled fit's own part (resolver-model fit|explain A.log B.log ...):
// each log's residual in the pooled fit and each log's parameters fitted alone
// against the pool's, the disagreeing ones first. The pooled fit itself prints as
// any fit (model_report.h).
#pragma once

#include <string>

#include "daemon/core/discovery/pool.h"

namespace resolver {

[[nodiscard]] std::string format_pool_text(const PooledExplanation& p);
/// The "pool" member: `,"pool":{...}` (to end a fit's JSON object with).
[[nodiscard]] std::string format_pool_json(const PooledExplanation& p);

}  // namespace resolver
