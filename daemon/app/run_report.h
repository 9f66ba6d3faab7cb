// The end-of-run report: what was read, what was rejected and why, what was
// estimated, and how much the compensation reduced position error and dq
// ripple. Printed as text for people and written as JSON for scripts.
#pragma once

#include <ostream>
#include <string>

#include "daemon/app/pipeline.h"

namespace resolver {

/// What became of the run's calibration (calibration_gate.h).
struct CalibrationOutcome {
  std::string path;     ///< the calibration file ("" without --state-dir)
  bool saved = false;
  std::string reason;   ///< why it was not saved (empty when saved)
};

struct RunInfo {
  std::string source;        ///< log path or interface
  double wall_seconds = 0.0; ///< processing wall time [s]
  CalibrationOutcome calibration;
};

void print_run_report(std::ostream& out, const Pipeline& pipeline, const RunInfo& info);
std::string run_report_json(const Pipeline& pipeline, const RunInfo& info);

}  // namespace resolver
