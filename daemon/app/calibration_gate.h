// Which calibration resolverd may keep, and which it may apply.
//
// A calibration saved at exit is applied at the next start before anything has
// been learned, so a wrong one compensates every angle wrongly until the new
// estimate converges. It is therefore saved only from a healthy run:
//   - the estimate converged;
//   - the live model fit (when [model] enabled) did not end on "unexplained": the
//     model does not describe this data, so its parameters describe nothing;
//   - no lasting signal fault (lasting_faults(), signal_health.h: one that held for
//     kUntrustedFaultShare of the samples or more; loss of tracking, of signal,
//     clipping, overspeed ...) covers the data the estimate was made from.
// And it is applied only on the layout it was learned on: the file records the
// layout's identity (layout_identity()) with the rest of its provenance, and a
// file from another layout is refused and moved aside, not applied
// (layout_identity(), pipeline.h).
#pragma once

#include <string>

#include "daemon/app/daemon_config.h"
#include "daemon/app/pipeline.h"
#include "daemon/service/calibration_store.h"

namespace resolver {

struct CalibrationJudgement {
  bool trusted = false;
  std::string reason;  ///< why not, every reason joined by "; " (empty when trusted)
};

/// Whether the run's estimate may be saved. Cannot fail.
[[nodiscard]] CalibrationJudgement judge_calibration(const Pipeline& pipeline);

/// 8 hex digits of CRC-32 of the file's text, "" when `path` is empty or unreadable.
[[nodiscard]] std::string file_crc32(const std::string& path);

/// Now in UTC, ISO 8601: "2026-11-26T01:44:32Z". `compact`: "20261126T014432Z" (for file names).
[[nodiscard]] std::string utc_now(bool compact = false);

}  // namespace resolver
