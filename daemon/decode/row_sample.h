// One sample that came as a row (a CSV / scope export), already in the roles'
// units (signal_map.h): the row-input counterpart of a joined BenchSample.
#pragma once

#include <array>
#include <cstdint>

#include "daemon/decode/signal_map.h"

namespace resolver {

struct RowSample {
  bool has_time = false;      ///< the export has a time column
  std::int64_t time_us = 0;   ///< [us] row time (has_time), any origin
  /// Data row number from 0, bad rows included: the sample number when there is
  /// no time column (time = sequence / row rate), so a bad row leaves a gap.
  std::int64_t sequence = 0;
  std::uint16_t roles = 0;    ///< role_bit() mask of valid values
  std::array<double, kRoleCount> values{};
};

}  // namespace resolver
