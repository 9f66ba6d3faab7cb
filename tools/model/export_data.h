// resolver-model export-data: a log's samples as the fit sees them, the fitted
// model's prediction and residual per sample, and the fitted parameters with
// units, for MATLAB, Python or a spreadsheet.
//
//   rows     prepare_log (daemon/core/discovery/prepare.h): one per sample with an
//            angle (and the reference when there is one), in time order; beside the
//            fit's columns, each row's raw signals as decoded (sin, cos, R/D angle,
//            reference angle, phase currents; NaN where the sample lacks one)
//   model    fit_prepared on the same rows; RowPredictor per row
//   CSV      OUT: the samples, one header line of column names (units in the names:
//            theta_rad, i_d_a), one line per row, NaN where a row lacks a signal.
//            MATLAB readtable(OUT), pandas.read_csv(OUT) and Python's csv read it as
//            one table. The parameters go to a second file, params_csv_path(OUT)
//            (name, value, std_error, unit): readtable reads one table per file.
//   MAT      OUT: one MAT-5 file (Debian libmatio, zlib-compressed; MATLAB load,
//            scipy.io.loadmat): structs samples (one N x 1 field per column), units
//            and descriptions (the same fields, text), params (name, unit: P x 1
//            cells; value, std_error: P x 1; struct2table(params) is the table),
//            info (log, model, pole pairs, angle source, residual and floor; the
//            numbers as 1 x 1 doubles, the rest as text).
//
// The prediction is the model's effects at the fitted values plus the constants
// fitted beside them (row_prediction.h: the dq operating point, the envelopes' gain,
// an angle offset without a reference), so measured - prediction over the fitted
// rows is the fit's residual.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"

namespace resolver {

struct ExportColumn {
  std::string name;         ///< identifier for MATLAB and pandas, unit as suffix: "theta_rad"
  std::string unit;         ///< "rad", "s", "A", "1", "r/min", "0/1" ...
  std::string description;  ///< one line, ASCII
  std::vector<double> values;
};

struct ExportTable {
  std::vector<ExportColumn> columns;                       ///< the samples, every column the same length
  std::vector<ModelParameter> params;                          ///< the fitted parameters
  /// key (an identifier), value: a number (p_r, residual_rms_rad ...) or text (log, model ...)
  std::vector<std::pair<std::string, std::variant<double, std::string>>> info;
  [[nodiscard]] std::size_t rows() const { return columns.empty() ? 0 : columns.front().values.size(); }
};

/// The table of `log` (prepared from `input`) and `fit` (fitted on it). `log_path` goes into info.
[[nodiscard]] ExportTable export_table(const DiscoveryInput& input, const PreparedLog& log, const ModelFit& fit,
                                       std::string_view log_path);

/// Where the CSV export puts the parameters: "x.csv" -> "x.params.csv", "x" -> "x.params.csv".
[[nodiscard]] std::string params_csv_path(const std::string& csv_path);

/// Writes the samples to `path` and the parameters to params_csv_path(path).
/// Throws std::system_error "cannot write <path>: <reason>".
void write_export_csv(const ExportTable& table, const std::string& path);

/// Writes the MAT-5 file. Throws std::system_error "cannot write <path>: <reason>".
void write_export_mat(const ExportTable& table, const std::string& path);

/// The whole subcommand: prepares the rows, fits `effects`, writes the CSV (when
/// csv_path is not empty) and the .mat (when mat_path is not empty). Returns what
/// was written, one line per file. Throws like fit_model and the writers.
[[nodiscard]] std::string export_data(const DiscoveryInput& input, std::span<const std::string> effects,
                                      const DiscoveryOptions& options, std::string_view log_path,
                                      const std::string& csv_path, const std::string& mat_path);

}  // namespace resolver
