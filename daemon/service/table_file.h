// The exported calibration table as files a drive firmware (or resolverd
// --calibration) loads: CSV, JSON and a C header, each with the model, the bench,
// the date, the table's indexing and interpolation and its error bound in a header
// (daemon/core/model/calibration_table.h defines the table).
//
// CSV, format 1 (what resolverd --calibration reads):
//   # resolver-bench calibration table, format 1
//   # key: value                      header lines (model, p_r, p, points, delay_s, ...)
//   index,theta_m_rad,correction_rad  the table: correction at the measured mechanical
//   0,0,1.23e-05                      angle 2 pi index / points
#pragma once

#include <string>

#include "daemon/core/model/calibration_table.h"

namespace resolver {

/// Where the table came from, for the header.
struct TableOrigin {
  std::string log;   ///< the log it was fitted on
  std::string date;  ///< ISO 8601 UTC
  std::string tool;  ///< e.g. "resolver-model 0.1.0 (git ...)"
};

[[nodiscard]] std::string format_table_csv(const CalibrationTable& t, const TableOrigin& o);
[[nodiscard]] std::string format_table_json(const CalibrationTable& t, const TableOrigin& o);
/// Throws std::invalid_argument when a value is NaN or infinite (C has no literal for them).
[[nodiscard]] std::string format_table_c_header(const CalibrationTable& t, const TableOrigin& o);

/// `value` as a C (C89 and later) and C++ floating literal that compiles on its own:
/// always with a '.' or an exponent, so 0 is "0.0f", -0 is "-0.0f" and 100 is
/// "100.0f", never the integer constant "0" that a suffix 'f' turns into an error.
/// `single`: a float literal ("%.9g", exact for every float, with the suffix 'f');
/// else a double (the shortest text that reads back the same double).
/// Throws std::invalid_argument for NaN or infinity.
[[nodiscard]] std::string c_float_literal(double value, bool single = true);

/// Reads a CSV table. Throws std::runtime_error naming the file, line and what is
/// wrong (not a table, a missing header key, a bad number, an index out of order).
[[nodiscard]] CalibrationTable read_table_csv(const std::string& path);

}  // namespace resolver
