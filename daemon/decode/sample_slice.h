// The part of a log a run looks at: --from S --to S [s] on the sample clock
// (t = 0 at the log's first sample). Samples outside are read (so time and
// counters stay right) but not used.
#pragma once

#include <limits>

namespace resolver {

struct SampleSlice {
  double from_s = 0.0;                                      ///< [s] first sample time used
  double to_s = std::numeric_limits<double>::infinity();    ///< [s] last sample time used

  [[nodiscard]] bool contains(double t) const { return t >= from_s && t <= to_s; }
  [[nodiscard]] bool limited() const { return from_s > 0.0 || to_s < std::numeric_limits<double>::infinity(); }
};

}  // namespace resolver
